// shade.wgsl — surfaces and shading: one invocation per ray of the band that hit something —
// the surface interaction (a free form's normal and leaf from its CSG program, freeform.wgsl;
// every other kind's from its hook through kinds.wgsl: a terrain's normal from its hit, a mesh's
// from its triangle), the cut face
// where the ray starts inside, then ambient +
// Lambert (albedo/π) + normalised Phong with each light seen through the RGB transmittance of a
// shadow ray that every primitive kind answers any-hit (fray-trace's Integrator, in f32), and
// through the media where the scene has them: the fog (fog_shading.wgsl), the clouds
// (clouds_shading.wgsl) and, for the sky's sun, the air (sky_shading.wgsl). Writes the radiance
// and the outward shading normal into the path. In a Whitted scene (whitted.wgsl) it also shades
// the queue's levels of secondary rays, spawns each hit's reflected and refracted rays, and
// shadow rays pass through transmissive surfaces. `shading` is the scene's group of lights and materials with its media's parameters and
// tables (bindings::shading); `surfaces` the other kinds' and the textures' (bindings::surfaces);
// kinds.wgsl, generated for the scene's kinds, calls their hooks.
//
// #bindings frame, free_forms, shading, surfaces
// #include "freeform.wgsl"
// #include "kinds.wgsl"
// #include "fog_shading.wgsl"
// #include "sky_shading.wgsl"
// #include "clouds_shading.wgsl"
// #include "whitted.wgsl"
// #include "texture.wgsl"
// #include "counters.wgsl"

override HAS_FREE_FORMS: bool = true;
override SHADOWS: bool = true;
override HAS_SUN: bool = true;
override HAS_POINT: bool = true;

// The RGB transmittance along the ray over [0, distance] (fray-trace's `transmittance`): the
// product over every primitive kind — every solid whole, every terrain exactly, every mesh
// instance — each opaque, so 0 where one is hit and 1 where none is; the first that blocks all
// light ends it.
fn transmittance(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> vec3<f32> {
    if whitted_transmits() {
        return whitted_transmittance(o, d, distance, eps);
    }
    if HAS_FREE_FORMS && occluded_by_solids(o, d, 0.0, distance, eps, frame.solids) {
        return vec3<f32>(0.0);
    }
    if kinds_occlude(o, d, distance, eps) {
        return vec3<f32>(0.0);
    }
    return vec3<f32>(1.0);
}

var<private> shadow_rays: u32;

fn radiance(p: vec3<f32>, n: vec3<f32>, to_viewer: vec3<f32>, m: GpuMaterial, eps: f32) -> vec3<f32> {
    var total = m.ambient.xyz * frame.ambient.xyz;
    let diffuse = m.diffuse.xyz / PI;
    let specular = m.specular.xyz;
    let specular_on = any(specular != vec3<f32>(0.0));
    let lobe_norm = (m.shininess + 2.0) / (2.0 * PI);
    for (var i = 0u; i < frame.lights; i++) {
        let light = lights[i];
        var to_light: vec3<f32>;
        var irradiance: vec3<f32>;
        var distance: f32;
        if light.kind == LIGHT_SUN {
            if !HAS_SUN {
                continue;
            }
            to_light = light.direction.xyz;
            irradiance = light.colour.xyz;
            distance = BIG;
        } else {
            if !HAS_POINT {
                continue;
            }
            let dl = light.position.xyz - p;
            let r2 = dot(dl, dl);
            if r2 == 0.0 {
                continue;
            }
            let r = sqrt(r2);
            to_light = dl / r;
            irradiance = light.colour.xyz / r2;
            distance = r;
        }
        let cos_l = dot(n, to_light);
        if cos_l <= 0.0 {
            continue;
        }
        // Not a shadow: the media dim the light whether or not shadows are on.
        let fog_t = fog_light_transmittance(p, light.kind, to_light, distance);
        let cloud_t = cloud_light_transmittance(p, to_light, distance);
        var light_in = irradiance * (fog_t * cloud_t * sky_light_transmittance(p, i));
        if SHADOWS {
            shadow_rays++;
            let through = transmittance(p + n * frame.shadow_offset, to_light, distance, eps);
            if all(through == vec3<f32>(0.0)) {
                continue;
            }
            light_in *= through;
        }
        var brdf = diffuse;
        if specular_on {
            let reflected = n * (2.0 * cos_l) - to_light;
            let rv = max(dot(reflected, to_viewer), 0.0);
            if rv > 0.0 {
                brdf += specular * (lobe_norm * pow(rv, m.shininess));
            }
        }
        total += brdf * light_in * cos_l;
    }
    return total;
}

@compute @workgroup_size(64)
fn main(at: QueueInvocation) {
    let k = begin_queue_kernel(at);
    shadow_rays = 0u;
    let range = shade_range();
    if k < range.y {
        let slot = range.x + k;
        whitted_begin(slot);
        let path = paths[slot];
        let t = path.hit.x;
        if path.origin.w >= 0.0 && t >= 0.0 {
            let p = path.origin.xyz + path.dir.xyz * t;
            let to_viewer = -path.dir.xyz;
            var normal: vec3<f32>;
            var geometric: vec3<f32>;
            var material: u32;
            if path.kind != KIND_FREE_FORM {
                let surface = kinds_shading(path);
                normal = surface.normal;
                geometric = surface.geometric;
                material = surface.material;
            } else {
                let surface = surface_at(path.index, p, to_viewer);
                normal = surface.normal;
                if path.part == FREE_FORM_BOX_EXIT {
                    // Left through its clipping box (secondary_hit.wgsl): that face's normal.
                    normal = path.hit.yzw;
                }
                geometric = normal;
                material = leaves[surface.leaf].material;
            }
            if t <= path.origin.w {
                // The picture surface cuts the object: the cut face, facing the viewer.
                normal = to_viewer;
                geometric = to_viewer;
            }
            var shading_normal = normal;
            if dot(normal, to_viewer) < 0.0 {
                shading_normal = -normal;
            }
            // The texture's or ramp's colour C times ka and kd (texture.wgsl), its footprint at
            // the path's length from the camera (t for a camera ray).
            let m = textured(materials[material], material, path, p, normal, whitted_path_length(slot, t));
            let colour = radiance(p, shading_normal, to_viewer, m, frame.epsilon);
            paths[slot].radiance = vec4<f32>(colour, 0.0);
            paths[slot].hit = vec4<f32>(t, normal);
            whitted_spawn(slot, p, path.dir.xyz, geometric, normal, m, t);
        } else {
            whitted_miss(slot);
        }
    }
    count(COUNT_SHADOW_RAYS, shadow_rays);
    end_queue_kernel(at);
}
