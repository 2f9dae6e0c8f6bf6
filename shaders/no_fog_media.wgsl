// no_fog_media.wgsl — the fog's hook in media.wgsl for a scene without fog (but with a sky):
// clear terms, and no layer for the ray to start in; no fog code or parameter is compiled.

struct FogMedia {
    terms: MediaTerms,
    starts_inside: bool,
}

fn fog_media(o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32) -> FogMedia {
    return FogMedia(MediaTerms(vec3<f32>(1.0), vec3<f32>(0.0)), false);
}
