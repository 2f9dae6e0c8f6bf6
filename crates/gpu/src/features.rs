//! The features a scene's shaders are composed and specialised with — the primitive kinds it
//! has, its media, Whitted's secondary rays, textures — as one set, each feature known by the
//! name a shader's `// #if <name>` tests. A new primitive kind is a feature by its
//! `PrimitiveKind` alone (named by `PrimitiveKind::name`); a new medium adds its variant here.

use fray_scene::{PrimitiveKind, Scene};

/// One feature a scene may have.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Feature {
    /// Primitives of this kind (`if terrain`, `if mesh`, `if free-form`).
    Kind(PrimitiveKind),
    /// A fog layer (`if fog`).
    Fog,
    /// A physically based sky (`if sky`).
    Sky,
    /// A cloud volume (`if clouds`).
    Clouds,
    /// Materials that reflect or transmit: Whitted's secondary rays (`if whitted`).
    Whitted,
    /// Image textures or colour ramps (`if textures`).
    Textures,
}

/// The features that are not a primitive kind, in the order they are described.
const OTHERS: [Feature; 5] = [
    Feature::Fog,
    Feature::Sky,
    Feature::Clouds,
    Feature::Whitted,
    Feature::Textures,
];

/// The bits the kinds take before the other features' (room for every kind code below it).
const KIND_BITS: u32 = 16;

impl Feature {
    /// Every feature: the kinds in their intersection order, then the others.
    pub fn all() -> impl Iterator<Item = Feature> {
        PrimitiveKind::ALL
            .into_iter()
            .map(Feature::Kind)
            .chain(OTHERS)
    }

    /// The name shaders test (`// #if <name>`) and stats print.
    pub const fn name(self) -> &'static str {
        match self {
            Feature::Kind(kind) => kind.name(),
            Feature::Fog => "fog",
            Feature::Sky => "sky",
            Feature::Clouds => "clouds",
            Feature::Whitted => "whitted",
            Feature::Textures => "textures",
        }
    }

    /// The feature called `name`, if one is.
    pub fn named(name: &str) -> Option<Feature> {
        Feature::all().find(|f| f.name() == name)
    }

    /// Whether it is a medium (the media pass runs for it).
    pub const fn is_medium(self) -> bool {
        matches!(self, Feature::Fog | Feature::Sky | Feature::Clouds)
    }

    const fn bit(self) -> u32 {
        match self {
            Feature::Kind(kind) => 1 << kind.code(),
            Feature::Fog => 1 << KIND_BITS,
            Feature::Sky => 1 << (KIND_BITS + 1),
            Feature::Clouds => 1 << (KIND_BITS + 2),
            Feature::Whitted => 1 << (KIND_BITS + 3),
            Feature::Textures => 1 << (KIND_BITS + 4),
        }
    }
}

/// A set of [`Feature`]s.
#[derive(Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Features(u32);

impl Features {
    /// No feature.
    pub const NONE: Features = Features(0);

    /// The features `scene` has.
    pub fn of_scene(scene: &Scene) -> Features {
        let f = &scene.features;
        let mut set = Features::NONE;
        for kind in PrimitiveKind::ALL {
            set = set.with_if(Feature::Kind(kind), scene.count(kind) > 0);
        }
        set.with_if(Feature::Fog, scene.atmosphere.fog.is_some())
            .with_if(Feature::Sky, scene.atmosphere.sky.is_some())
            .with_if(Feature::Clouds, scene.clouds.is_some())
            .with_if(Feature::Whitted, f.reflection || f.transmission)
            .with_if(Feature::Textures, f.textures)
    }

    /// Every feature.
    pub fn every() -> Features {
        Feature::all().fold(Features::NONE, Features::with)
    }

    /// The set with `feature` in it.
    pub const fn with(self, feature: Feature) -> Features {
        Features(self.0 | feature.bit())
    }

    /// The set with `feature` in it where `on`, without it otherwise.
    pub const fn with_if(self, feature: Feature, on: bool) -> Features {
        if on {
            self.with(feature)
        } else {
            Features(self.0 & !feature.bit())
        }
    }

    /// Whether `feature` is in the set.
    pub const fn has(self, feature: Feature) -> bool {
        self.0 & feature.bit() != 0
    }

    /// Whether the scene has a primitive of `kind`.
    pub const fn has_kind(self, kind: PrimitiveKind) -> bool {
        self.has(Feature::Kind(kind))
    }

    /// Whether any medium is in the set (the media pass runs).
    pub fn media(self) -> bool {
        OTHERS.iter().any(|f| f.is_medium() && self.has(*f))
    }

    /// The features in the set, in [`Feature::all`]'s order.
    pub fn iter(self) -> impl Iterator<Item = Feature> {
        Feature::all().filter(move |f| self.has(*f))
    }

    /// Whether a shader condition holds: `""` always, `"if <name>"` / `"unless <name>"` by the
    /// named feature; `None` for anything else (an unknown name, a malformed condition).
    pub fn condition(self, rest: &str) -> Option<bool> {
        let rest = rest.trim();
        if rest.is_empty() {
            return Some(true);
        }
        let (negated, name) = match rest.split_once(' ') {
            Some(("if", name)) => (false, name),
            Some(("unless", name)) => (true, name),
            _ => return None,
        };
        Feature::named(name.trim()).map(|f| self.has(f) != negated)
    }
}

impl std::fmt::Debug for Features {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_set()
            .entries(self.iter().map(Feature::name))
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every feature has its own bit and its own name, and is found by it.
    #[test]
    fn every_feature_has_its_own_bit_and_name() {
        let all: Vec<_> = Feature::all().collect();
        for (i, a) in all.iter().enumerate() {
            assert_eq!(Feature::named(a.name()), Some(*a));
            assert_eq!(Features::NONE.with(*a).iter().collect::<Vec<_>>(), [*a]);
            for b in &all[i + 1..] {
                assert_ne!(a.bit(), b.bit(), "{a:?} {b:?}");
                assert_ne!(a.name(), b.name());
            }
        }
        assert!(PrimitiveKind::ALL.iter().all(|k| k.code() < KIND_BITS));
    }

    #[test]
    fn conditions_test_the_named_feature() {
        let set = Features::NONE.with(Feature::Fog);
        assert_eq!(set.condition(""), Some(true));
        assert_eq!(set.condition("if fog"), Some(true));
        assert_eq!(set.condition("unless fog"), Some(false));
        assert_eq!(set.condition("if terrain"), Some(false));
        assert_eq!(set.condition(" unless  terrain "), Some(true));
        assert_eq!(set.condition("if fgo"), None);
        assert_eq!(set.condition("when fog"), None);
        assert!(set.media() && !Features::NONE.with(Feature::Whitted).media());
    }
}
