//! Primitive ids: every surface a ray can hit is named by its kind and its index within the
//! kind — the pair that hits, work-list candidates, materials and the GPU all use, instead of
//! one id space with offsets.

/// The kinds of primitive a scene holds. Each kind answers the same few questions in each
/// backend (bounds, nearest hit over a ray range, transmittance over a ray range, the surface at
/// a hit); `ARCHITECTURE.md` lists what adding one takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(u32)]
pub enum PrimitiveKind {
    /// A free-form CSG solid: [`crate::Scene::objects`].
    FreeForm = 0,
    /// A height-map terrain: [`crate::Scene::terrains`].
    Terrain = 1,
    /// A triangle-mesh instance: [`crate::Scene::meshes`].
    Mesh = 2,
}

impl PrimitiveKind {
    /// Every kind, in the order the backends intersect them (a tie between kinds keeps the
    /// earlier kind's hit).
    pub const ALL: [PrimitiveKind; 3] = [
        PrimitiveKind::FreeForm,
        PrimitiveKind::Terrain,
        PrimitiveKind::Mesh,
    ];

    /// The kind's number in work lists and GPU buffers.
    pub const fn code(self) -> u32 {
        self as u32
    }

    /// The kind of a work-list or GPU code, if it names one.
    pub const fn from_code(code: u32) -> Option<Self> {
        match code {
            0 => Some(PrimitiveKind::FreeForm),
            1 => Some(PrimitiveKind::Terrain),
            2 => Some(PrimitiveKind::Mesh),
            _ => None,
        }
    }

    /// A short lower-case name, e.g. `"free-form"`.
    pub const fn name(self) -> &'static str {
        match self {
            PrimitiveKind::FreeForm => "free-form",
            PrimitiveKind::Terrain => "terrain",
            PrimitiveKind::Mesh => "mesh",
        }
    }
}

/// One primitive of a scene: its kind and its index among the scene's primitives of that kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct PrimitiveId {
    pub kind: PrimitiveKind,
    pub index: u32,
}

impl PrimitiveId {
    pub const fn new(kind: PrimitiveKind, index: u32) -> Self {
        Self { kind, index }
    }

    /// Free form `index` ([`crate::Scene::objects`]).
    pub const fn free_form(index: u32) -> Self {
        Self::new(PrimitiveKind::FreeForm, index)
    }

    /// Terrain `index` ([`crate::Scene::terrains`]).
    pub const fn terrain(index: u32) -> Self {
        Self::new(PrimitiveKind::Terrain, index)
    }

    /// Mesh `index` ([`crate::Scene::meshes`]).
    pub const fn mesh(index: u32) -> Self {
        Self::new(PrimitiveKind::Mesh, index)
    }

    /// The id of a work-list candidate (`None` for a kind code no scene uses).
    pub fn of_candidate(c: &fray_quadtree::Candidate) -> Option<Self> {
        PrimitiveKind::from_code(c.kind).map(|kind| Self::new(kind, c.object))
    }
}

impl std::fmt::Display for PrimitiveId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {}", self.kind.name(), self.index)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip_and_unknown_codes_are_none() {
        for kind in PrimitiveKind::ALL {
            assert_eq!(PrimitiveKind::from_code(kind.code()), Some(kind));
        }
        assert_eq!(PrimitiveKind::from_code(3), None);
        let c = fray_quadtree::Candidate::new(1, 7, 0, 0, 0.0, 1.0);
        assert_eq!(PrimitiveId::of_candidate(&c), Some(PrimitiveId::terrain(7)));
        assert_eq!(PrimitiveId::terrain(7).to_string(), "terrain 7");
    }
}
