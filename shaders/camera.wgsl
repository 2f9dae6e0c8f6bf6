// camera.wgsl — the projector's ray through an image point: fray_core::Projector::ray in f32,
// camera-relative (the eye at the origin), for pinhole, parallel and sphere picture surfaces.

override PROJECTOR: u32 = 0u;

struct CameraRay {
    origin: vec3<f32>,
    dir: vec3<f32>,
    t_near: f32,
    ok: bool,
}

// The ray through image point (x, y) in pixel units (pixel centres at +0.5).
fn camera_ray(x: f32, y: f32) -> CameraRay {
    let w = f32(max(frame.width, 1u));
    let h = f32(max(frame.height, 1u));
    let aspect = w / h;
    let u = x * (2.0 / w) - 1.0;
    let sx = u * aspect;
    let sy = 1.0 - y * (2.0 / h);
    let forward = frame.forward.xyz;
    let right = frame.right.xyz;
    let up = frame.up.xyz;
    var c = vec3<f32>(0.0);
    var d = vec3<f32>(0.0);
    var r: CameraRay;
    if PROJECTOR == PROJECTOR_PINHOLE {
        let k = frame.forward.w;
        d = (forward + right * (sx * k) + up * (sy * k)) * frame.right.w;
    } else if PROJECTOR == PROJECTOR_PARALLEL {
        let half = frame.forward.w;
        c = right * (sx * half) + up * (sy * half);
        if frame.right.w == 0.0 {
            r.origin = c;
            r.dir = forward;
            r.t_near = 0.0;
            r.ok = true;
            return r;
        }
        d = forward * frame.right.w;
    } else {
        let theta = 0.5 * frame.sphere.x * u;
        let phi = 0.5 * frame.sphere.y * sy;
        let dir = forward * (cos(phi) * cos(theta)) + right * (cos(phi) * sin(theta)) + up * sin(phi);
        let radius = frame.centre.w
            * (1.0 + frame.sphere.z * cos(frame.sphere.w * theta) * cos(frame.sphere.w * phi));
        d = frame.centre.xyz + dir * radius;
    }
    let len = length(d);
    r.origin = c;
    r.ok = len > 0.0;
    r.dir = d / max(len, 1e-30);
    r.t_near = len;
    return r;
}
