// sky_media.wgsl — the sky's hook in media.wgsl for a scene with a sky (sky.wgsl): a miss's
// background is the sky-view table and, where drawn, the sun's disc (Media::background); a hit
// sees its surface through the air over [0, t_hit] from the ray's origin, when the scene asks
// for aerial perspective (Media::terms). For a miss the march runs over an empty path (t = 0:
// zero-length steps, exactly clear terms) rather than under a branch on the hit — straight-line,
// as sky.wgsl explains.
//
// #if sky
// #include "sky.wgsl"

fn media_background(d: vec3<f32>) -> vec3<f32> {
    return sky_background(d);
}

// The air over [0, t] when t is finite (a surface's or a cloud's distance) and the scene draws
// aerial perspective; clear terms otherwise.
fn media_air(o: vec3<f32>, d: vec3<f32>, t: f32, finite: bool) -> MediaTerms {
    let aerial = (sky.flags & SKY_AERIAL_PERSPECTIVE) != 0u;
    let air = sky_aerial_perspective(o, d, select(0.0, t, finite && aerial));
    return MediaTerms(air.transmittance, air.in_scatter);
}

// #else
// Without it: the sky's hook in media.wgsl for a scene without a sky (but with fog):
// the scene's background colour and no air; no sky code, parameter or table is compiled.

fn media_background(d: vec3<f32>) -> vec3<f32> {
    return frame.background.xyz;
}

fn media_air(o: vec3<f32>, d: vec3<f32>, t: f32, finite: bool) -> MediaTerms {
    return MediaTerms(vec3<f32>(1.0), vec3<f32>(0.0));
}
// #endif
