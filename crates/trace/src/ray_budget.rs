//! Whitted's secondary-ray budget (`settings.max_secondary_rays`): how many secondary rays one
//! camera ray (sample) may trace, whatever the depth. The tree of reflected and refracted rays
//! is otherwise exponential in `max_depth` (two children per hit on glass: `2^(d + 1) − 2` rays).
//!
//! The rule: a camera ray starts with the budget as its *allowance* (secondary rays its tree may
//! still trace). A hit's children — the reflected and the refracted ray that pass the
//! contribution cut-off, in that order — share their parent's allowance: two get `⌈a/2⌉` and
//! `⌊a/2⌋`, one gets all of `a`. A child whose share is 0 is not traced (it brings back 0, as a
//! ray below the cut-off does); a traced child spends one ray of its share and passes the rest,
//! `share − 1`, on to its own children. By induction no tree traces more rays than its
//! allowance, and a tree of `max_depth` levels fits whole when the budget is at least
//! `2^(max_depth + 1) − 2` (each full subtree's need is its share exactly).
//!
//! Why this rule: a ray's share depends only on its own path from the camera — never on how
//! many rays were traced before it — so the CPU, recursing depth first, and the GPU, tracing a
//! band's rays level by level in whatever order its invocations run, trace exactly the same
//! rays, and the image does not depend on threads or order. (A "first N rays" counter would
//! differ between depth-first and breadth-first order; a weight floor bounds the count only
//! when `kr + kt ≤ 1`, which the materials do not promise — each may be up to 1.) The cost:
//! a lopsided tree (a reflection that escapes to the sky beside a refraction that keeps going)
//! leaves the escaped ray's share unused.

/// The shares of a ray's two children — the reflected and the refracted ray, `present` where it
/// passes the contribution cut-off — of `allowance`: the secondary rays each child's tree may
/// trace, itself included (0: not traced).
#[inline]
pub fn shares(allowance: u32, present: [bool; 2]) -> [u32; 2] {
    match present {
        [true, true] => [allowance.div_ceil(2), allowance / 2],
        [true, false] => [allowance, 0],
        [false, true] => [0, allowance],
        [false, false] => [0, 0],
    }
}

#[cfg(test)]
mod tests {
    use super::shares;

    /// The rays a full binary tree of `levels` levels below a ray with `allowance` traces under
    /// the rule.
    fn full_tree(allowance: u32, levels: u32) -> u64 {
        if levels == 0 {
            return 0;
        }
        shares(allowance, [true, true])
            .iter()
            .filter(|&&s| s > 0)
            .map(|&s| 1 + full_tree(s - 1, levels - 1))
            .sum()
    }

    /// Shares add up to the allowance (nothing is created), in the order the children come.
    #[test]
    fn shares_split_the_allowance_reflected_first() {
        for a in 0..100 {
            let [r, t] = shares(a, [true, true]);
            assert_eq!(r + t, a);
            assert!(r >= t && r - t <= 1);
            assert_eq!(shares(a, [true, false]), [a, 0]);
            assert_eq!(shares(a, [false, true]), [0, a]);
            assert_eq!(shares(a, [false, false]), [0, 0]);
        }
    }

    /// A full tree never traces more rays than the budget, and fits whole exactly when the
    /// budget is at least `2^(d + 1) − 2`.
    #[test]
    fn a_full_tree_fits_whole_from_the_full_count() {
        for levels in 1..=10 {
            let whole = (1u64 << (levels + 1)) - 2;
            for budget in [0, 1, 2, 3, 7, 100, 1000, 5000] {
                let traced = full_tree(budget, levels);
                assert!(traced <= u64::from(budget), "{levels} levels, {budget}");
                assert_eq!(traced == whole, u64::from(budget) >= whole);
            }
            assert_eq!(full_tree(whole as u32, levels), whole);
            assert!(full_tree(whole as u32 - 1, levels) < whole);
        }
    }
}
