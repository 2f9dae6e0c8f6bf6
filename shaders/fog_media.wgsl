// fog_media.wgsl — the fog's hook in media.wgsl for a scene with fog: the layer's terms over a
// camera ray's [lo, hi] (FogLayer::terms; fog.wgsl): T = e^{−τ} and L_in = albedo · (ambient ·
// (1 − e^{−τ}) + Σ suns E · factor) — point lights do not scatter in fog — with the sky's sun
// reaching the layer's top through the air above it (fog.sky_sun_transmittance, from f64), and
// whether the ray starts inside the layer (which decides whether the fog is in front of the
// air).
//
// #if fog
// #include "fog.wgsl"

struct FogMedia {
    terms: MediaTerms,
    starts_inside: bool,
}

fn fog_media(o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32) -> FogMedia {
    let s = fog_segment(o, d, lo, hi);
    var light = frame.ambient.xyz * fog_ambient_factor(s);
    for (var i = 0u; i < frame.lights; i++) {
        let sun = lights[i];
        if sun.kind != LIGHT_SUN {
            continue;
        }
        let top = select(vec3<f32>(1.0), fog.sky_sun_transmittance.xyz, i == fog.sky_sun);
        light += sun.colour.xyz * top * fog_sun_factor(o, d, s, sun.direction.xyz);
    }
    var out: FogMedia;
    out.terms = MediaTerms(vec3<f32>(fog_segment_transmittance(s)), select(vec3<f32>(0.0), fog.albedo.xyz * light, s.inside));
    // FogLayer::span starting at lo: the ray is in the layer from its first point on.
    out.starts_inside = s.span.x <= s.span.y && s.span.x <= lo;
    return out;
}

// #else
// Without it: the fog's hook in media.wgsl for a scene without fog (but with a sky):
// clear terms, and no layer for the ray to start in; no fog code or parameter is compiled.

struct FogMedia {
    terms: MediaTerms,
    starts_inside: bool,
}

fn fog_media(o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32) -> FogMedia {
    return FogMedia(MediaTerms(vec3<f32>(1.0), vec3<f32>(0.0)), false);
}
// #endif
