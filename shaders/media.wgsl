// media.wgsl — the media pass, between shade and resolve: one invocation per ray of the band,
// the radiance arriving at the camera through the scene's media (fray-trace's Media, in f32):
// `T · L_surface + L_in` over [t_near, t_hit] for a ray that hit, `T · background + L_in` over
// [t_near, ∞) for one that did not. The fog's terms (fog_media.wgsl) cover the segment inside
// the layer; the sky's air (sky_media.wgsl) adds the aerial perspective in front of a surface,
// and a miss's background is the sky (its table and the sun's disc) seen through the fog. Fog
// and air are composed as two layers in the order the ray enters them, as the CPU does: the fog
// in front when the ray starts inside it, the air in front otherwise. A cloud volume
// (clouds_media.wgsl) is marched where the ray crosses its box and inserted at its entry, the
// atmosphere in front of it and behind it. A scene without one of them includes its
// no_*_media.wgsl twin (clear terms; the plain background; the atmosphere alone). Built only
// for scenes with fog, a sky or clouds; resolve then takes every ray's radiance, misses
// included (its HAS_MEDIA). Counts the cloud march's density samples of camera rays. In a
// Whitted scene it also takes each level of secondary rays through the media before their
// parents gather them (whitted_media.wgsl; fray-trace's through_media and miss_radiance: no
// pixel's jitter, no samples counted).
//
// #bindings frame, shading
// #include "ray.wgsl"
// #include "fog_media.wgsl"
// #include "sky_media.wgsl"
// #include "clouds_media.wgsl"
// #include "whitted_media.wgsl"
// #include "counters.wgsl"

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

// `a` where `c` is false, `b` where it is true (select, for terms).
fn media_select(a: MediaTerms, b: MediaTerms, c: bool) -> MediaTerms {
    return MediaTerms(select(a.transmittance, b.transmittance, c), select(a.in_scatter, b.in_scatter, c));
}

// The fog's terms and the air's composed in the order the ray enters them (Media's
// atmosphere_terms): the fog in front when the ray starts inside it, the air otherwise.
fn media_atmosphere_with(fog: FogMedia, air: MediaTerms) -> MediaTerms {
    return media_select(media_then(air, fog.terms), media_then(fog.terms, air), fog.starts_inside);
}

// The cloud march's density samples of this invocation's ray (set by media_terms).
var<private> cloud_samples: u32;

@compute @workgroup_size(64)
fn main(at: QueueInvocation) {
    let k = begin_queue_kernel(at);
    cloud_samples = 0u;
    let range = media_range();
    let slot = range.x + k;
    // No ray (a degenerate projector pair, origin.w < 0): resolve shows the background, as the
    // CPU does. With anti-aliasing the centre ray (ray 0 of its pixel) gives depth and normal
    // only: its colour is never read, so its media are not computed (nor counted).
    if k < range.y && media_colour_ray(slot) && paths[slot].origin.w >= 0.0 {
        let path = paths[slot];
        let o = path.origin.xyz;
        let d = path.dir.xyz;
        let hit = path.hit.x >= 0.0;
        let behind = select(media_background(d), path.radiance.xyz, hit);
        let pixel_ray = media_pixel_ray(slot);
        let terms = media_terms(o, d, path.origin.w, select(BIG, path.hit.x, hit), hit, pixel_ray);
        paths[slot].radiance = vec4<f32>(behind * terms.transmittance + terms.in_scatter, 0.0);
        if pixel_ray == NO_PIXEL {
            cloud_samples = 0u;
        }
    }
    count(COUNT_CLOUD_SAMPLES, cloud_samples);
    end_queue_kernel(at);
}
