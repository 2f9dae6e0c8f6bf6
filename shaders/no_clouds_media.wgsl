// no_clouds_media.wgsl — the clouds' hook in media.wgsl for a scene without clouds (but with fog
// or a sky): the atmosphere's terms over the ray's range alone; no cloud code, parameter or
// texture is compiled.

fn media_terms(o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32, hit: bool, ray: u32) -> MediaTerms {
    return media_atmosphere_with(fog_media(o, d, lo, hi), media_air(o, d, hi, hit));
}
