//! The one evaluator of the postfix CSG program, generic over what a value is ([`CsgAlgebra`]).
//!
//! A [`Solid`](crate::Solid)'s program (`Leaf`, `Max`, `Min`, `Neg` on a stack) means the same
//! thing whatever is computed with it: a point value, a value with the leaf that decides it, a
//! value with its gradient, a value and slope range over a ray segment, a set of ray parameters,
//! the program folded over absent leaves. Each of those is an *algebra* — what a leaf is and what
//! `max`, `min` and negation do to two (one) of them — and [`run`] is the one interpreter, as
//! fidget runs one tape through several evaluator families. It is always inlined, so each algebra
//! gets its own monomorphised loop with the algebra's operations inlined into it.
//!
//! The shapes that dominate after culling — one leaf; two leaves under a union, intersection or
//! difference — are matched before the loop and run without a stack (the values stay in
//! registers; without this the loop costs the csg frame 6 % more instructions). Longer programs run on a stack of [`INLINE_DEPTH`] values on the machine stack
//! that spills deeper ones to the heap ([`run`]), or on the caller's `Vec` ([`run_in`]).

use super::CsgOp;

/// What a program computes: the value of a leaf and the three operations on values.
///
/// Every operation may give up (`None`), which ends the run with `None` — a span set that
/// outgrows its capacity, a leaf index out of range. The operations are called in program order,
/// once per op, so an algebra may have effects (the fold emits its output program as it goes).
pub trait CsgAlgebra {
    type Value: Copy;
    /// The value of leaf `i`.
    fn leaf(&mut self, i: u32) -> Option<Self::Value>;
    /// Union.
    fn max(&mut self, a: Self::Value, b: Self::Value) -> Option<Self::Value>;
    /// Intersection.
    fn min(&mut self, a: Self::Value, b: Self::Value) -> Option<Self::Value>;
    /// Complement.
    fn neg(&mut self, a: Self::Value) -> Option<Self::Value>;
}

/// Stack entries [`run`] keeps on the machine stack before it spills to the heap: eight covers
/// every program of up to eight leaves and long chains of unions (depth 2); a deeper stack is
/// rare (a right-nested chain of differences).
pub const INLINE_DEPTH: usize = 8;

/// Runs `program` over `algebra`: the value of the program, or `None` if an operation gave up or
/// the program is malformed (an operator short of operands, or more than one value left). The
/// stack lives on the machine stack up to [`INLINE_DEPTH`] values and spills to the heap beyond
/// (allocating only then).
#[inline(always)]
pub fn run<A: CsgAlgebra>(program: &[CsgOp], algebra: &mut A) -> Option<A::Value> {
    let mut spill = Vec::new();
    let first = match shortcut(program, algebra) {
        Start::Done(value) => return value,
        Start::Loop(first) => first,
    };
    let stack = Inline {
        inline: [first; INLINE_DEPTH],
        len: 1,
        spill: &mut spill,
    };
    interpret(&program[1..], algebra, stack)
}

/// [`run`] with `stack` (cleared first) as the evaluation stack: for values too large to keep
/// [`INLINE_DEPTH`] copies of on the machine stack (span sets), and for programs evaluated again
/// and again that may be deep (the caster's), which then allocate once.
#[inline(always)]
pub fn run_in<A: CsgAlgebra>(
    program: &[CsgOp],
    algebra: &mut A,
    stack: &mut Vec<A::Value>,
) -> Option<A::Value> {
    let first = match shortcut(program, algebra) {
        Start::Done(value) => return value,
        Start::Loop(first) => first,
    };
    stack.clear();
    stack.push(first);
    interpret(&program[1..], algebra, Heap(stack))
}

/// How a run starts: finished by a shortcut, or with the first leaf's value for the loop.
enum Start<V> {
    Done(Option<V>),
    Loop(V),
}

/// The shapes that culling leaves most often — one leaf; two under a union, intersection or
/// difference — with no stack at all; otherwise the first leaf's value (a well-formed program
/// starts with a leaf).
#[inline(always)]
fn shortcut<A: CsgAlgebra>(program: &[CsgOp], algebra: &mut A) -> Start<A::Value> {
    Start::Done(match *program {
        [CsgOp::Leaf(i)] => algebra.leaf(i),
        [
            CsgOp::Leaf(i),
            CsgOp::Leaf(j),
            op @ (CsgOp::Max | CsgOp::Min),
        ] => two_leaves(algebra, i, j, false, op),
        [
            CsgOp::Leaf(i),
            CsgOp::Leaf(j),
            CsgOp::Neg,
            op @ (CsgOp::Max | CsgOp::Min),
        ] => two_leaves(algebra, i, j, true, op),
        [CsgOp::Leaf(first), ..] => match algebra.leaf(first) {
            Some(first) => return Start::Loop(first),
            None => None,
        },
        _ => None,
    })
}

/// `op(i, j)`, or `op(i, −j)` if `negate`.
#[inline(always)]
fn two_leaves<A: CsgAlgebra>(
    algebra: &mut A,
    i: u32,
    j: u32,
    negate: bool,
    op: CsgOp,
) -> Option<A::Value> {
    let a = algebra.leaf(i)?;
    let b = algebra.leaf(j)?;
    let b = if negate { algebra.neg(b)? } else { b };
    combine(algebra, op, a, b)
}

/// The loop over the ops after the first, on a stack that holds the first leaf's value.
#[inline(always)]
fn interpret<A: CsgAlgebra, S: Stack<A::Value>>(
    ops: &[CsgOp],
    algebra: &mut A,
    mut stack: S,
) -> Option<A::Value> {
    for &op in ops {
        match op {
            CsgOp::Leaf(i) => {
                let v = algebra.leaf(i)?;
                stack.push(v);
            }
            CsgOp::Neg => {
                let top = stack.top()?;
                *top = algebra.neg(*top)?;
            }
            CsgOp::Max | CsgOp::Min => {
                let b = stack.pop()?;
                let top = stack.top()?;
                *top = combine(algebra, op, *top, b)?;
            }
        }
    }
    stack.only()
}

/// `max` or `min` as `op` says.
#[inline(always)]
fn combine<A: CsgAlgebra>(
    algebra: &mut A,
    op: CsgOp,
    a: A::Value,
    b: A::Value,
) -> Option<A::Value> {
    if op == CsgOp::Max {
        algebra.max(a, b)
    } else {
        algebra.min(a, b)
    }
}

/// An evaluation stack.
trait Stack<V> {
    fn push(&mut self, v: V);
    fn pop(&mut self) -> Option<V>;
    fn top(&mut self) -> Option<&mut V>;
    /// The result: the one value left.
    fn only(self) -> Option<V>;
}

/// The first [`INLINE_DEPTH`] entries inline, the rest in `spill`.
struct Inline<'s, V> {
    inline: [V; INLINE_DEPTH],
    len: usize,
    spill: &'s mut Vec<V>,
}

impl<V: Copy> Stack<V> for Inline<'_, V> {
    #[inline(always)]
    fn push(&mut self, v: V) {
        if let Some(slot) = self.inline.get_mut(self.len) {
            *slot = v;
        } else {
            self.spill.push(v);
        }
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<V> {
        self.len = self.len.checked_sub(1)?;
        match self.inline.get(self.len) {
            Some(&v) => Some(v),
            None => self.spill.pop(),
        }
    }

    #[inline(always)]
    fn top(&mut self) -> Option<&mut V> {
        let k = self.len.checked_sub(1)?;
        match self.inline.get_mut(k) {
            Some(v) => Some(v),
            None => self.spill.last_mut(),
        }
    }

    #[inline(always)]
    fn only(self) -> Option<V> {
        (self.len == 1).then_some(self.inline[0])
    }
}

/// All entries in the caller's `Vec`.
struct Heap<'s, V>(&'s mut Vec<V>);

impl<V: Copy> Stack<V> for Heap<'_, V> {
    #[inline(always)]
    fn push(&mut self, v: V) {
        self.0.push(v);
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<V> {
        self.0.pop()
    }

    #[inline(always)]
    fn top(&mut self) -> Option<&mut V> {
        self.0.last_mut()
    }

    #[inline(always)]
    fn only(self) -> Option<V> {
        match self.0[..] {
            [v] => Some(v),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use CsgOp::{Leaf, Max, Min, Neg};

    /// Leaves as given numbers; counts the operations it is asked for.
    struct Numbers<'a> {
        leaves: &'a [f64],
        ops: usize,
    }

    impl CsgAlgebra for Numbers<'_> {
        type Value = f64;
        fn leaf(&mut self, i: u32) -> Option<f64> {
            self.ops += 1;
            self.leaves.get(i as usize).copied()
        }
        fn max(&mut self, a: f64, b: f64) -> Option<f64> {
            self.ops += 1;
            Some(a.max(b))
        }
        fn min(&mut self, a: f64, b: f64) -> Option<f64> {
            self.ops += 1;
            Some(a.min(b))
        }
        fn neg(&mut self, a: f64) -> Option<f64> {
            self.ops += 1;
            Some(-a)
        }
    }

    /// A plain recursive reference: the value of the operand ending at `end` (exclusive), and
    /// where that operand starts.
    fn reference(program: &[CsgOp], leaves: &[f64], end: usize) -> (f64, usize) {
        match program[end - 1] {
            Leaf(i) => (leaves[i as usize], end - 1),
            Neg => {
                let (v, start) = reference(program, leaves, end - 1);
                (-v, start)
            }
            op => {
                let (b, mid) = reference(program, leaves, end - 1);
                let (a, start) = reference(program, leaves, mid);
                (if op == Max { a.max(b) } else { a.min(b) }, start)
            }
        }
    }

    /// A random well-formed program over `n` leaves (each once), nested both ways so that the
    /// stack gets deep.
    fn program(n: u32, next: &mut impl FnMut() -> u64) -> Vec<CsgOp> {
        let mut operands: Vec<Vec<CsgOp>> = (0..n).map(|i| vec![Leaf(i)]).collect();
        while operands.len() > 1 {
            let k = (next() as usize) % (operands.len() - 1);
            let b = operands.remove(k + 1);
            let a = &mut operands[k];
            a.extend(b);
            match next() % 3 {
                0 => a.push(Max),
                1 => a.push(Min),
                _ => a.extend([Neg, Min]),
            }
        }
        operands.pop().unwrap_or_default()
    }

    #[test]
    fn runs_like_a_recursive_reference_at_every_depth() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut spill = Vec::new();
        let mut deepest = 0;
        for _ in 0..4000 {
            let n = 1 + (next() % 24) as u32;
            let program = program(n, &mut next);
            let leaves: Vec<f64> = (0..n).map(|_| (next() % 2001) as f64 - 1000.0).collect();
            let (want, start) = reference(&program, &leaves, program.len());
            assert_eq!(start, 0);
            let mut algebra = Numbers {
                leaves: &leaves,
                ops: 0,
            };
            let got = run_in(&program, &mut algebra, &mut spill);
            assert_eq!(got, Some(want), "{program:?} {leaves:?}");
            assert_eq!(algebra.ops, program.len(), "one call per op");
            let mut fresh = Numbers {
                leaves: &leaves,
                ops: 0,
            };
            assert_eq!(run(&program, &mut fresh), Some(want));
            let mut depth = 0usize;
            let mut max_depth = 0;
            for op in &program {
                match op {
                    Leaf(_) => depth += 1,
                    Max | Min => depth -= 1,
                    Neg => {}
                }
                max_depth = max_depth.max(depth);
            }
            deepest = deepest.max(max_depth);
        }
        assert!(deepest > INLINE_DEPTH + 2, "the spill was exercised");
    }

    #[test]
    fn malformed_programs_and_failing_operations_give_none() {
        let leaves = [1.0, -2.0, 3.0];
        let mut numbers = Numbers {
            leaves: &leaves,
            ops: 0,
        };
        for program in [
            &[][..],
            &[Max],
            &[Neg],
            &[Leaf(0), Max],
            &[Leaf(0), Leaf(1)],
            &[Leaf(0), Leaf(1), Leaf(2), Max],
            &[Leaf(0), Neg, Neg, Min],
        ] {
            assert_eq!(run(program, &mut numbers), None, "{program:?}");
        }
        // Leaf 7 does not exist: the algebra gives up, in a shortcut and in the loop.
        assert_eq!(run(&[Leaf(0), Leaf(7), Max], &mut numbers), None);
        assert_eq!(
            run(&[Leaf(0), Leaf(1), Max, Leaf(7), Min], &mut numbers),
            None
        );
        assert_eq!(
            run(&[Leaf(0), Leaf(1), Neg, Max, Leaf(2), Min], &mut numbers),
            Some(2.0)
        );
    }
}
