// media.wgsl — the media pass, between shade and resolve: one invocation per ray of the band,
// the radiance arriving at the camera through the scene's media (fray-trace's Media, in f32):
// `T · L_surface + L_in` over [t_near, t_hit] for a ray that hit, `T · background + L_in` over
// [t_near, ∞) for one that did not. The fog's terms (fog_media.wgsl) cover the segment inside
// the layer; the sky's air (sky_media.wgsl) adds the aerial perspective in front of a surface,
// and a miss's background is the sky (its table and the sun's disc) seen through the fog. Fog
// and air are composed as two layers in the order the ray enters them, as the CPU does: the fog
// in front when the ray starts inside it, the air in front otherwise. A scene without one of
// them includes its no_*_media.wgsl twin (clear terms; the plain background). Built only for
// scenes with fog or a sky; resolve then takes every ray's radiance, misses included (its
// HAS_MEDIA).
//
// #bindings frame, shading
// #include "ray.wgsl"
// #include "fog_media.wgsl" if fog
// #include "no_fog_media.wgsl" unless fog
// #include "sky_media.wgsl" if sky
// #include "no_sky_media.wgsl" unless sky

// What a medium does to a ray segment: L_eye = transmittance · L_behind + in_scatter
// (fray-trace's MediaTerms).
struct MediaTerms {
    transmittance: vec3<f32>,
    in_scatter: vec3<f32>,
}

// `front` in front of `behind` (MediaTerms::then).
fn media_then(front: MediaTerms, behind: MediaTerms) -> MediaTerms {
    return MediaTerms(front.transmittance * behind.transmittance, front.transmittance * behind.in_scatter + front.in_scatter);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    if k >= frame.width * frame.band_rows * frame.rays_per_pixel {
        return;
    }
    let path = paths[k];
    if path.origin.w < 0.0 {
        // No ray (a degenerate projector pair): resolve shows the background, as the CPU does.
        return;
    }
    let o = path.origin.xyz;
    let d = path.dir.xyz;
    let hit = path.hit.x >= 0.0;
    let behind = select(media_background(d), path.radiance.xyz, hit);
    let fog = fog_media(o, d, path.origin.w, select(BIG, path.hit.x, hit));
    let air = media_air(o, d, path.hit.x, hit);
    let fog_first = media_then(fog.terms, air);
    let air_first = media_then(air, fog.terms);
    let t = select(air_first.transmittance, fog_first.transmittance, fog.starts_inside);
    let l = select(air_first.in_scatter, fog_first.in_scatter, fog.starts_inside);
    paths[k].radiance = vec4<f32>(behind * t + l, 0.0);
}
