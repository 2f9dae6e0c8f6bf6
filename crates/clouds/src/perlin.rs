//! Ken Perlin's improved noise (2002), exactly as his reference implementation computes it: the
//! lattice cell of the point (coordinates wrapped to 0..=255), the permutation table's hash of each
//! corner, the gradient of the hash's low 4 bits (12 directions, 4 of them repeated) dotted with the
//! offset from the corner, blended by the fade `6t⁵ − 15t⁴ + 10t³`. f64 is the reference; the f32
//! version runs the same steps in f32 (what a GPU twin computes).

/// Perlin's permutation of 0..=255.
pub const PERMUTATION: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69,
    142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219,
    203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175,
    74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60, 211, 133, 230,
    220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76,
    132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173,
    186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163,
    70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232,
    178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162,
    241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204,
    176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141,
    128, 195, 78, 66, 215, 61, 156, 180,
];

/// The permutation twice over, so that `p[p[x] + y]` needs no wrap (Perlin's `p[512]`).
const P: [u8; 512] = {
    let mut p = [0u8; 512];
    let mut i = 0;
    while i < 512 {
        p[i] = PERMUTATION[i % 256];
        i += 1;
    }
    p
};

#[inline]
fn p(i: usize) -> usize {
    usize::from(P[i])
}

/// Perlin's noise, its fade, lerp, grad and lattice cell, in one float type: instantiated for f64
/// (the reference) and f32 (what a shader computes), so the two cannot drift apart.
macro_rules! improved_noise {
    ($float:ty, $noise:ident, $fade:ident, $grad:ident, $doc:literal) => {
        /// The fade curve `6t⁵ − 15t⁴ + 10t³`.
        #[inline]
        pub fn $fade(t: $float) -> $float {
            t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
        }

        /// Perlin's `grad`: the dot product of the hash's gradient (one of 12 edge directions
        /// of a cube, by its low 4 bits) with `(x, y, z)`.
        #[inline]
        pub fn $grad(hash: usize, x: $float, y: $float, z: $float) -> $float {
            let h = hash & 15;
            let u = if h < 8 { x } else { y };
            let v = if h < 4 {
                y
            } else if h == 12 || h == 14 {
                x
            } else {
                z
            };
            (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
        }

        #[doc = $doc]
        pub fn $noise(x: $float, y: $float, z: $float) -> $float {
            // The lattice cell (wrapped to 0..=255, as Perlin's `(int)floor(x) & 255` does for
            // negative coordinates too; `as i64` saturates for huge values, and `& 255` of a
            // saturated value is still an index) and the offset in it.
            let cell = |x: $float| {
                let f = x.floor();
                ((f as i64 & 255) as usize, x - f)
            };
            let lerp = |t: $float, a: $float, b: $float| a + t * (b - a);
            let (xi, x) = cell(x);
            let (yi, y) = cell(y);
            let (zi, z) = cell(z);
            let (u, v, w) = ($fade(x), $fade(y), $fade(z));
            let a = p(xi) + yi;
            let (aa, ab) = (p(a) + zi, p(a + 1) + zi);
            let b = p(xi + 1) + yi;
            let (ba, bb) = (p(b) + zi, p(b + 1) + zi);
            lerp(
                w,
                lerp(
                    v,
                    lerp(u, $grad(p(aa), x, y, z), $grad(p(ba), x - 1.0, y, z)),
                    lerp(
                        u,
                        $grad(p(ab), x, y - 1.0, z),
                        $grad(p(bb), x - 1.0, y - 1.0, z),
                    ),
                ),
                lerp(
                    v,
                    lerp(
                        u,
                        $grad(p(aa + 1), x, y, z - 1.0),
                        $grad(p(ba + 1), x - 1.0, y, z - 1.0),
                    ),
                    lerp(
                        u,
                        $grad(p(ab + 1), x, y - 1.0, z - 1.0),
                        $grad(p(bb + 1), x - 1.0, y - 1.0, z - 1.0),
                    ),
                ),
            )
        }
    };
}

improved_noise!(
    f64,
    noise,
    fade,
    grad,
    "Improved noise at `(x, y, z)`, in f64: Perlin's reference implementation step for step."
);
improved_noise!(
    f32,
    noise_f32,
    fade_f32,
    grad_f32,
    "[`noise`] computed in f32 throughout (the cell from the f32 coordinate, f32 fade, gradients and blends): what a shader computes."
);
