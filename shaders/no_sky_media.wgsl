// no_sky_media.wgsl — the sky's hook in media.wgsl for a scene without a sky (but with fog):
// the scene's background colour and no air; no sky code, parameter or table is compiled.

fn media_background(d: vec3<f32>) -> vec3<f32> {
    return frame.background.xyz;
}

fn media_air(o: vec3<f32>, d: vec3<f32>, t: f32, finite: bool) -> MediaTerms {
    return MediaTerms(vec3<f32>(1.0), vec3<f32>(0.0));
}
