// secondary_hit.wgsl — the nearest hit of a ray leaving a surface (Whitted's reflected and
// refracted rays, shadow rays through glass), over every primitive kind with no work list: the
// f32 twin of fray-trace's nearest_hit_from_surface. Kinds in the CPU's order (free forms,
// terrains, meshes; a tie keeps the earlier), the range (0, nearest so far). A ray that starts
// inside a transmissive free form (its solid's value ≥ 0 at the origin) finds where it leaves
// it: the first point of the solid's complement (its program negated, GpuSolid's
// complement_word) or, a solid cut by its box, the box's far face (Interiors::exit_hit). The
// including module has freeform.wgsl and the scene's kinds' hooks (kinds.wgsl).

// Whether `o` lies inside solid `si` (Solid::eval(o) ≥ 0): its program at the point, every leaf
// present whose box holds it.
fn inside_solid(si: u32, o: vec3<f32>) -> bool {
    let solid = solids[si];
    let along = vec3<f32>(0.0, 0.0, 1.0);
    let at = clip_box(solid.box_min.xyz, solid.box_max.xyz, o, along, 0.0, 0.0);
    if at.x > at.y {
        return false;
    }
    if !prepare(si, all_parts(si), o, along, 0.0) {
        return false;
    }
    cast_program = vec2<u32>(solid.first_word, solid.word_count);
    cast_first_leaf = solid.first_leaf;
    return solid_value(0.0) >= 0.0;
}

// The outward normal of the face of box [lo, hi] nearest to p (Aabb::face_normal).
fn box_face_normal(lo: vec3<f32>, hi: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
    var best = BIG;
    var n = vec3<f32>(1.0, 0.0, 0.0);
    for (var axis = 0u; axis < 3u; axis++) {
        let below = abs(p[axis] - lo[axis]);
        let above = abs(hi[axis] - p[axis]);
        if below < best {
            best = below;
            n = vec3<f32>(0.0);
            n[axis] = -1.0;
        }
        if above < best {
            best = above;
            n = vec3<f32>(0.0);
            n[axis] = 1.0;
        }
    }
    return n;
}

// Narrows `best` to the nearest free-form hit in (0, best), or (0, limit) before the first.
fn free_forms_nearest(o: vec3<f32>, d: vec3<f32>, limit: f32, eps: f32, best: ptr<function, SurfaceHit>) {
    for (var si = 0u; si < frame.solids; si++) {
        let hi = select(limit, (*best).t, (*best).t >= 0.0);
        let solid = solids[si];
        if solid.complement_word != 0u && inside_solid(si, o) {
            var parts = all_parts(si);
            parts.program = vec2<u32>(solid.complement_word, solid.word_count + 1u);
            let t = cast_solid(si, parts, o, d, 0.0, hi, eps);
            if t >= 0.0 {
                if (*best).t < 0.0 || t < (*best).t {
                    *best = SurfaceHit(t, KIND_FREE_FORM, si, 0u, vec3<f32>(0.0));
                }
                continue;
            }
            let inside = clip_box(solid.box_min.xyz, solid.box_max.xyz, o, d, 0.0, hi);
            if inside.x <= inside.y && inside.y < hi {
                let face = box_face_normal(solid.box_min.xyz, solid.box_max.xyz, o + d * inside.y);
                *best = SurfaceHit(inside.y, KIND_FREE_FORM, si, FREE_FORM_BOX_EXIT, face);
            }
            continue;
        }
        let t = cast_solid(si, all_parts(si), o, d, 0.0, hi, eps);
        if t >= 0.0 && ((*best).t < 0.0 || t < (*best).t) {
            *best = SurfaceHit(t, KIND_FREE_FORM, si, 0u, vec3<f32>(0.0));
        }
    }
}

// The nearest hit over every kind of a ray from `o` along `d` (unit) in (0, limit).
fn nearest_from_surface(o: vec3<f32>, d: vec3<f32>, limit: f32, eps: f32) -> SurfaceHit {
    var best = SurfaceHit(NO_HIT, 0u, 0u, 0u, vec3<f32>(0.0));
    if HAS_FREE_FORMS {
        free_forms_nearest(o, d, limit, eps, &best);
    }
    kinds_nearest_from_surface(o, d, limit, eps, &best);
    return best;
}

// The material of hit `h` of the ray from `o` along `d`: a free form's leaf at the point, a
// terrain's, a mesh instance's.
fn surface_hit_material(h: SurfaceHit, o: vec3<f32>, d: vec3<f32>) -> u32 {
    if h.kind != KIND_FREE_FORM {
        return kinds_material(h.kind, h.index);
    }
    return leaves[surface_at(h.index, o + d * h.t, -d).leaf].material;
}
