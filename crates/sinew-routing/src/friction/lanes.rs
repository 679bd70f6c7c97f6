//! The wrap angles' `atan2` and the capstan factors' `exp` over many holes at once, `libm`'s
//! (the Rust port of musl, from FreeBSD's `msun`; error below 1 ulp) bit for bit, with the
//! holes' sines taken by vector square roots.
//!
//! A hole's wrap angle `θ = atan2(|u_in × u_out|, u_in · u_out)` and its capstan factor
//! `e^{σμθ}` are the friction geometry's two transcendental functions, one call each per hole;
//! called one hole at a time they were a quarter of a stick evaluation at 50 DOF
//! (docs/performance.md, #27). Here each is `libm`'s own algorithm along its main path (the
//! same reduction, the same polynomial and constants, the same operations in the same order,
//! and no fused multiply-add, which Rust never forms on its own), written on pulp's vectors
//! (`f64s`: four values in an AVX2 register, two with SSE2) with its branches turned into
//! selects, inside pulp's runtime dispatch. A value off that path (zero with a negative or
//! zero `x`, infinities, NaN, ratios beyond `2^±60`, exponents beyond `ln 2 / 2`) goes to
//! `libm` itself in its vector's place, and so do the last values that fill no vector. So
//! each result is `libm`'s bit for bit; the tests below hold that to account on about a
//! million values, the edges of every branch among them.

// `libm::atan`'s constants (FreeBSD `s_atan.c`): `atan` of the breakpoints 0.5, 1, 1.5 and ∞ in
// two parts, and the polynomial.
const ATAN_HI: [f64; 4] = [
    f64::from_bits(0x3fdd_ac67_0561_bb4f),
    f64::from_bits(0x3fe9_21fb_5444_2d18),
    f64::from_bits(0x3fef_730b_d281_f69b),
    f64::from_bits(0x3ff9_21fb_5444_2d18),
];
const ATAN_LO: [f64; 4] = [
    f64::from_bits(0x3c7a_2b7f_222f_65e2),
    f64::from_bits(0x3c81_a626_3314_5c07),
    f64::from_bits(0x3c70_0788_7af0_cbbd),
    f64::from_bits(0x3c91_a626_3314_5c07),
];
const AT: [f64; 11] = [
    f64::from_bits(0x3fd5_5555_5555_550d),
    f64::from_bits(0xbfc9_9999_9998_ebc4),
    f64::from_bits(0x3fc2_4924_9200_83ff),
    f64::from_bits(0xbfbc_71c6_fe23_1671),
    f64::from_bits(0x3fb7_45cd_c54c_206e),
    f64::from_bits(0xbfb3_b0f2_af74_9a6d),
    f64::from_bits(0x3fb1_0d66_a0d0_3d51),
    f64::from_bits(0xbfad_de2d_52de_fd9a),
    f64::from_bits(0x3fa9_7b4b_2476_0deb),
    f64::from_bits(0xbfa2_b444_2c6a_6c2f),
    f64::from_bits(0x3f90_ad3a_e322_da11),
];
// `libm::atan2`'s π in two parts.
const PI: f64 = f64::from_bits(0x4009_21fb_5444_2d18);
const PI_LO: f64 = f64::from_bits(0x3ca1_a626_3314_5c07);
// `libm::exp`'s polynomial (FreeBSD `e_exp.c`).
const P: [f64; 5] = [
    f64::from_bits(0x3fc5_5555_5555_553e),
    f64::from_bits(0xbf66_c16c_16be_bd93),
    f64::from_bits(0x3f11_566a_af25_de2c),
    f64::from_bits(0xbebb_bd41_c5d2_6bf1),
    f64::from_bits(0x3e66_3769_72be_a4d0),
];

/// The smallest and largest `|y/x|` given to the vector `atan2`: inside, `libm::atan2` takes its
/// main path (`atan(|y/x|)`, then `π −` it for `x < 0`); outside, its special cases may apply
/// (a ratio beyond 2^±64 by exponents, zero, infinity, NaN), so the value goes to `libm`.
const RATIO_MIN: f64 = f64::from_bits(0x3c30_0000_0000_0000); // 2^-60
const RATIO_MAX: f64 = f64::from_bits(0x43b0_0000_0000_0000); // 2^60
/// `s_atan.c` returns `t` itself below this (high word `0x3e400000`, 2^-27).
const ATAN_TINY: f64 = f64::from_bits(0x3e40_0000_0000_0000);

/// The range of `|x|` where `libm::exp` takes its main path with no scaling (`k = 0`): high word
/// of `|x|` above `0x3e300000` (`|x| > 2^-28`) and at most `0x3fd62e42` (`|x| ≤ ln 2 / 2`).
const EXP_MIN: f64 = f64::from_bits(0x3e30_0001_0000_0000);
const EXP_END: f64 = f64::from_bits(0x3fd6_2e43_0000_0000);

/// `out[i] = libm::atan2(y[i], x[i])` for every `i`, bit for bit (module docs). `y` and `out`
/// may not overlap; the three slices have one length (the shortest is used).
pub(crate) fn atan2_all(y: &[f64], x: &[f64], out: &mut [f64]) {
    let n = out.len().min(y.len()).min(x.len());
    let (y, x, out) = (&y[..n], &x[..n], &mut out[..n]);
    let done = pulp::Arch::new().dispatch(Blocks { x, y: Some(y), out });
    for i in done..n {
        out[i] = libm::atan2(y[i], x[i]);
    }
}

/// `out[i] = libm::exp(x[i])` for every `i`, bit for bit (module docs); the two slices have one
/// length (the shorter is used).
pub(crate) fn exp_all(x: &[f64], out: &mut [f64]) {
    let n = out.len().min(x.len());
    let (x, out) = (&x[..n], &mut out[..n]);
    let done = pulp::Arch::new().dispatch(Blocks { x, y: None, out });
    for i in done..n {
        out[i] = libm::exp(x[i]);
    }
}

/// `x[i] = √x[i]` for every `i`, in place (IEEE square roots, correctly rounded in a vector
/// as one by one).
pub(crate) fn sqrt_all(x: &mut [f64]) {
    struct Roots<'a>(&'a mut [f64]);
    impl pulp::WithSimd for Roots<'_> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, simd: S) {
            let (head, tail) = S::as_mut_simd_f64s(self.0);
            for v in head {
                *v = simd.sqrt_f64s(*v);
            }
            for v in tail {
                *v = v.sqrt();
            }
        }
    }
    pulp::Arch::new().dispatch(Roots(x));
}

/// The vector pass of [`atan2_all`] (`y` given) or [`exp_all`] as a pulp operation: every
/// whole vector of values along the main path, its values off that path by `libm`; the number
/// of values done (the rest, fewer than a vector, are left to the caller).
struct Blocks<'a> {
    x: &'a [f64],
    y: Option<&'a [f64]>,
    out: &'a mut [f64],
}

impl pulp::WithSimd for Blocks<'_> {
    type Output = usize;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> usize {
        let Blocks { x, y, out } = self;
        let lanes = S::F64_LANES;
        let (xs, _) = S::as_simd_f64s(x);
        let (zero, one) = (simd.splat_f64s(0.0), simd.splat_f64s(1.0));
        // Whether a vector has a value off the main path (rare: a straight hole's zero angle
        // and exponent); those values then go to `libm`, in their place.
        let any_off = |main: S::m64s| simd.reduce_sum_f64s(simd.select_f64s(main, zero, one)) > 0.0;
        match y {
            Some(y) => {
                let (ys, _) = S::as_simd_f64s(y);
                for (b, (xv, yv)) in xs.iter().zip(ys).enumerate() {
                    let (value, main) = atan2_main(simd, *yv, *xv);
                    let block = b * lanes..(b + 1) * lanes;
                    store(&mut out[block.clone()], value);
                    if any_off(main) {
                        for i in block.filter(|&i| !atan2_on_main_path(y[i], x[i])) {
                            out[i] = libm::atan2(y[i], x[i]);
                        }
                    }
                }
            }
            None => {
                for (b, xv) in xs.iter().enumerate() {
                    let (value, main) = exp_main(simd, *xv);
                    let block = b * lanes..(b + 1) * lanes;
                    store(&mut out[block.clone()], value);
                    if any_off(main) {
                        for i in block.filter(|&i| !exp_on_main_path(x[i])) {
                            out[i] = libm::exp(x[i]);
                        }
                    }
                }
            }
        }
        xs.len() * lanes
    }
}

/// A vector's values into `out` (its length).
#[inline(always)]
fn store<V: pulp::bytemuck::Pod>(out: &mut [f64], value: V) {
    out.copy_from_slice(pulp::bytemuck::cast_slice(std::slice::from_ref(&value)));
}

/// Whether `libm::atan2(y, x)` takes the main path [`atan2_main`] follows.
fn atan2_on_main_path(y: f64, x: f64) -> bool {
    (RATIO_MIN..=RATIO_MAX).contains(&(y / x.abs())) || (y == 0.0 && 0.0 < x && x < f64::INFINITY)
}

/// Whether `libm::exp(x)` takes the main path [`exp_main`] follows.
fn exp_on_main_path(x: f64) -> bool {
    (EXP_MIN..EXP_END).contains(&x.abs()) || x == 0.0
}

/// `libm::atan2(y, x)` along its main path, lane by lane, and which lanes take it: `|y/x|` in
/// `[2^-60, 2^60]` (so `y > 0` and `x` finite and non-zero), or `y = ±0` and `x` finite and
/// positive, where `libm` returns `y` and the path gives `y / |x| = y` (a straight hole, an
/// anchor).
#[inline(always)]
fn atan2_main<S: pulp::Simd>(simd: S, y: S::f64s, x: S::f64s) -> (S::f64s, S::m64s) {
    let c = |v: f64| simd.splat_f64s(v);
    // `fabs(y / x)`, as `y / |x|` (IEEE division is exact in sign).
    let t = simd.div_f64s(y, simd.abs_f64s(x));
    let z = atan_main(simd, t);
    let reflected = simd.sub_f64s(c(PI), simd.sub_f64s(z, c(PI_LO)));
    let value = simd.select_f64s(simd.less_than_f64s(x, c(0.0)), reflected, z);
    let in_range = simd.and_m64s(
        simd.greater_than_or_equal_f64s(t, c(RATIO_MIN)),
        simd.less_than_or_equal_f64s(t, c(RATIO_MAX)),
    );
    let straight = simd.and_m64s(
        simd.equal_f64s(y, c(0.0)),
        simd.and_m64s(simd.greater_than_f64s(x, c(0.0)), simd.less_than_f64s(x, c(f64::INFINITY))),
    );
    (value, simd.or_m64s(in_range, straight))
}

/// `libm::atan(t)` for `t ≥ 0` below `2^66`, lane by lane: the interval of `t` selects the
/// reduction (numerator and denominator of one division) and the breakpoint's `atan`.
#[inline(always)]
fn atan_main<S: pulp::Simd>(simd: S, t: S::f64s) -> S::f64s {
    let c = |v: f64| simd.splat_f64s(v);
    let (add, sub, mul) =
        (|a, b| simd.add_f64s(a, b), |a, b| simd.sub_f64s(a, b), |a, b| simd.mul_f64s(a, b));
    // The high-word tests of `s_atan.c` as comparisons of the value (exact: each bound's low
    // word is zero): 0x3fdc0000 = 0.4375, 0x3fe60000 = 0.6875, 0x3ff30000 = 1.1875,
    // 0x40038000 = 2.4375.
    let below = |v: f64| simd.less_than_f64s(t, c(v));
    let (b, b0, b1, b2) = (below(0.4375), below(0.6875), below(1.1875), below(2.4375));
    // A select over the four reductions (`b`: none, then breakpoints 0.5, 1, 1.5 and ∞).
    let pick = |none: S::f64s, v: [S::f64s; 4]| {
        let from = simd.select_f64s(
            b0,
            v[0],
            simd.select_f64s(b1, v[1], simd.select_f64s(b2, v[2], v[3])),
        );
        simd.select_f64s(b, none, from)
    };
    let numerator = pick(t, [sub(mul(c(2.), t), c(1.)), sub(t, c(1.)), sub(t, c(1.5)), c(-1.)]);
    let denominator = pick(c(1.), [add(c(2.), t), add(t, c(1.)), add(c(1.), mul(c(1.5), t)), t]);
    let atan_hi = pick(c(0.0), ATAN_HI.map(c));
    let atan_lo = pick(c(0.0), ATAN_LO.map(c));
    // `t / 1` is `t`: the reduction of `t < 0.4375` is none.
    let x = simd.div_f64s(numerator, denominator);
    let z = mul(x, x);
    let w = mul(z, z);
    let even = |k: usize| c(AT[k]);
    let s1 = mul(
        z,
        add(
            even(0),
            mul(
                w,
                add(
                    even(2),
                    mul(
                        w,
                        add(even(4), mul(w, add(even(6), mul(w, add(even(8), mul(w, even(10))))))),
                    ),
                ),
            ),
        ),
    );
    let s2 = mul(
        w,
        add(
            even(1),
            mul(w, add(even(3), mul(w, add(even(5), mul(w, add(even(7), mul(w, even(9)))))))),
        ),
    );
    let sum = add(s1, s2);
    let small = sub(x, mul(x, sum));
    let large = sub(atan_hi, sub(sub(mul(x, sum), atan_lo), x));
    simd.select_f64s(below(ATAN_TINY), t, simd.select_f64s(b, small, large))
}

/// `libm::exp(x)` along its main path without scaling (`2^-28 < |x| ≤ ln 2 / 2`), lane by lane,
/// and which lanes take it (those and `±0`).
#[inline(always)]
fn exp_main<S: pulp::Simd>(simd: S, x: S::f64s) -> (S::f64s, S::m64s) {
    let c = |v: f64| simd.splat_f64s(v);
    let (add, sub, mul) =
        (|a, b| simd.add_f64s(a, b), |a, b| simd.sub_f64s(a, b), |a, b| simd.mul_f64s(a, b));
    let (hi, lo) = (x, c(0.0));
    let xx = mul(x, x);
    let p = add(
        c(P[0]),
        mul(xx, add(c(P[1]), mul(xx, add(c(P[2]), mul(xx, add(c(P[3]), mul(xx, c(P[4])))))))),
    );
    let r = sub(x, mul(xx, p));
    // `1 + (x c / (2 − c) − lo + hi)`.
    let y = add(c(1.), add(sub(simd.div_f64s(mul(x, r), sub(c(2.), r)), lo), hi));
    let a = simd.abs_f64s(x);
    let main = simd.and_m64s(
        simd.greater_than_or_equal_f64s(a, c(EXP_MIN)),
        simd.less_than_f64s(a, c(EXP_END)),
    );
    // At ±0 the path gives 1 + (0 − 0 + x) = 1, `libm`'s `1 + x` (a straight hole's factor).
    (y, simd.or_m64s(main, simd.equal_f64s(x, c(0.0))))
}

#[cfg(test)]
mod tests {
    //! Each function against `libm` bit for bit: on the wrap geometry's own inputs (the sine
    //! and cosine of every angle from 0 to π), on values across the exponent range, at and
    //! around every breakpoint of the algorithms and the bounds of the main path, and on the
    //! special values, mixed in blocks (a block of four with one irregular value must send
    //! that one to `libm` and keep the others) and with tails of one to three. A wrong
    //! coefficient, breakpoint, reduction or select, or an irregular value kept, fails here.

    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::{atan2_all, exp_all};

    /// The algorithms' bounds, written here from `libm`'s sources, not read from the module.
    const BOUND_2_M27: f64 = 7.450580596923828e-9; // s_atan.c: t itself below
    const BOUND_2_M60: f64 = 8.673617379884035e-19;
    const BOUND_2_P60: f64 = 1.152921504606847e18;
    const EXP_LOW: f64 = 3.7252903e-9; // e_exp.c: high word 0x3e300000, 2^-28
    const EXP_HIGH: f64 = 0.34657359; // high word 0x3fd62e42: ln 2 / 2

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// `v` and its neighbours `k` ulps either side (positive `v`).
    fn around(v: f64, k: u64) -> impl Iterator<Item = f64> {
        let b = v.to_bits();
        (b.saturating_sub(k)..=b + k).map(f64::from_bits)
    }

    fn check_atan2(y: &[f64], x: &[f64]) {
        // Every length, and every offset of the block boundaries.
        for start in 0..4.min(y.len()) {
            let (y, x) = (&y[start..], &x[start..]);
            let mut out = vec![0.0; y.len()];
            atan2_all(y, x, &mut out);
            for i in 0..y.len() {
                let want = libm::atan2(y[i], x[i]);
                assert!(
                    same(out[i], want),
                    "atan2({:e}, {:e}) = {:e}, libm {want:e}",
                    y[i],
                    x[i],
                    out[i]
                );
            }
        }
    }

    fn check_exp(x: &[f64]) {
        for start in 0..4.min(x.len()) {
            let x = &x[start..];
            let mut out = vec![0.0; x.len()];
            exp_all(x, &mut out);
            for i in 0..x.len() {
                let want = libm::exp(x[i]);
                assert!(same(out[i], want), "exp({:e}) = {:e}, libm {want:e}", x[i], out[i]);
            }
        }
    }

    #[test]
    fn atan2_of_wrap_angles_is_libm_bit_for_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(27);
        let (mut y, mut x) = (Vec::new(), Vec::new());
        for i in 0..400_000 {
            // Two unit directions at an angle from 0 to π (some nearly straight, some nearly
            // reversed), as the friction geometry forms them.
            let theta: f64 = match i % 4 {
                0 => rng.random_range(0.0..std::f64::consts::PI),
                1 => rng.random_range(0.0..1e-6),
                2 => std::f64::consts::PI - rng.random_range(0.0..1e-6),
                _ => rng.random_range(0.0..0.6),
            };
            let (s, c) = theta.sin_cos();
            let u = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 1.0];
            let n = (u[0] * u[0] + u[1] * u[1] + 1.0f64).sqrt();
            let scale = 1.0 / n;
            // Rounded as a computed cross product's norm and dot product are.
            y.push((s * scale * n).abs());
            x.push(c * scale * n);
        }
        check_atan2(&y, &x);
    }

    #[test]
    fn atan2_across_exponents_breakpoints_and_special_values_is_libm_bit_for_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(2027);
        let (mut y, mut x) = (Vec::new(), Vec::new());
        for _ in 0..400_000 {
            let e: i32 = rng.random_range(-80..80);
            let f: i32 = rng.random_range(-80..80);
            let sy = if rng.random_bool(0.1) { -1.0 } else { 1.0 };
            let sx = if rng.random_bool(0.5) { -1.0 } else { 1.0 };
            y.push(sy * rng.random_range(1.0..2.0) * 2f64.powi(e));
            x.push(sx * rng.random_range(1.0..2.0) * 2f64.powi(f));
        }
        // Ratios at and around every breakpoint of `atan` and the bounds of the main path.
        let bounds =
            [0.4375, 0.6875, 1.1875, 2.4375, BOUND_2_M27, BOUND_2_M60, BOUND_2_P60, 1.0, 0.5];
        for b in bounds {
            for t in around(b, 3) {
                for x0 in [1.0, -1.0, 0.75, -3.0] {
                    y.push(t * f64::abs(x0));
                    x.push(x0);
                }
            }
        }
        let special =
            [0.0, -0.0, 1.0, -1.0, f64::INFINITY, -f64::INFINITY, f64::NAN, 1e-300, 5e-324];
        for &a in &special {
            for &b in &special {
                y.push(a);
                x.push(b);
                // An irregular value among regular ones in a block.
                y.extend([0.3, a, 0.2, 0.1]);
                x.extend([0.9, b, -0.5, 1.0]);
            }
        }
        check_atan2(&y, &x);
    }

    #[test]
    fn exp_is_libm_bit_for_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut x: Vec<f64> = (0..400_000)
            .map(|i| match i % 3 {
                // Capstan exponents σμθ: μ up to 1, θ up to π.
                0 => rng.random_range(-0.35..0.35),
                1 => rng.random_range(-1e-6..1e-6),
                _ => rng.random_range(-3.2..3.2),
            })
            .collect();
        // Either side of each bound of the main path, to the last bit of the high word.
        for b in [EXP_LOW, EXP_HIGH] {
            let high = b.to_bits() >> 32;
            for h in [high - 1, high, high + 1, high + 2] {
                for low in [0, 1, 0x7fff_ffff, 0xffff_fffe, 0xffff_ffff] {
                    let v = f64::from_bits(h << 32 | low);
                    x.extend([v, -v]);
                }
            }
            for _ in 0..2000 {
                let v = b * rng.random_range(0.999..1.001);
                x.extend([v, -v]);
            }
        }
        let special = [0.0, -0.0, 1e-300, 800.0, -800.0, f64::INFINITY, -f64::INFINITY, f64::NAN];
        for &a in &special {
            x.extend([a, 0.1, 0.2, a, -0.05]);
        }
        check_exp(&x);
    }
}
