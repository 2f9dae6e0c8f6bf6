//! Wrap modes: what a lookup outside the uv square `[0, 1]²` reads — the texture repeated, its
//! edge texels extended, or the texture mirrored at every edge — chosen per axis.

/// How one axis treats coordinates outside `[0, 1]`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum WrapMode {
    /// Tiled: `u` and `u + 1` read the same texel; bilinear lookups blend across the seam.
    #[default]
    Repeat,
    /// The edge texels extend outward; bilinear lookups never read across the edge (a draped
    /// image or a decal).
    Clamp,
    /// Tiled with every other copy flipped (period 2): seamless without a tileable image.
    Mirror,
}

/// A wrap mode per axis: `u` (columns) and `v` (rows).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Wrap {
    /// Along `u` (the image's columns).
    pub u: WrapMode,
    /// Along `v` (the image's rows).
    pub v: WrapMode,
}

impl Wrap {
    /// [`WrapMode::Repeat`] on both axes.
    pub const REPEAT: Self = Self::both(WrapMode::Repeat);
    /// [`WrapMode::Clamp`] on both axes.
    pub const CLAMP: Self = Self::both(WrapMode::Clamp);
    /// [`WrapMode::Mirror`] on both axes.
    pub const MIRROR: Self = Self::both(WrapMode::Mirror);

    /// The same mode on both axes.
    pub const fn both(mode: WrapMode) -> Self {
        Self { u: mode, v: mode }
    }
}

impl WrapMode {
    /// `x` brought into a small range that reads the same texels: `[0, 1)` (repeat), `[0, 2)`
    /// (mirror), `[0, 1]` (clamp); so lookups at huge coordinates keep their precision and
    /// never overflow an index. A non-finite coordinate reads as 0.
    #[inline]
    pub fn reduce(self, x: f64) -> f64 {
        if !x.is_finite() {
            return 0.0;
        }
        match self {
            WrapMode::Repeat => x - x.floor(),
            WrapMode::Mirror => x - 2.0 * (0.5 * x).floor(),
            WrapMode::Clamp => x.clamp(0.0, 1.0),
        }
    }

    /// The texel index that integer index `i` of a `n`-texel axis reads (`n ≥ 1`).
    #[inline]
    pub fn index(self, i: i64, n: u32) -> u32 {
        let n = i64::from(n);
        if (0..n).contains(&i) {
            return i as u32; // inside: every mode agrees (and no division)
        }
        let k = match self {
            WrapMode::Repeat => i.rem_euclid(n),
            WrapMode::Clamp => i.clamp(0, n - 1),
            WrapMode::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        };
        k as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_wrap_clamp_and_mirror() {
        let n = 3;
        let idx = |m: WrapMode| (-4..7).map(|i| m.index(i, n)).collect::<Vec<_>>();
        assert_eq!(idx(WrapMode::Repeat), [2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0]);
        assert_eq!(idx(WrapMode::Clamp), [0, 0, 0, 0, 0, 1, 2, 2, 2, 2, 2]);
        assert_eq!(idx(WrapMode::Mirror), [2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0]);
        assert_eq!(WrapMode::Repeat.reduce(-0.25), 0.75);
        assert_eq!(WrapMode::Mirror.reduce(-0.25), 1.75);
        assert_eq!(WrapMode::Clamp.reduce(7.0), 1.0);
        for m in [WrapMode::Repeat, WrapMode::Clamp, WrapMode::Mirror] {
            assert_eq!(m.reduce(f64::NAN), 0.0);
            assert!(m.reduce(1e300).is_finite() && m.reduce(-1e300).is_finite());
        }
    }
}
