//! `scalar::sqrt_f32` against the correctly rounded square root.
//!
//! The reference is `(x as f64).sqrt() as f32`: `f64` carries 53 ≥ 2·24 + 2 bits, so rounding
//! the `f64` root to `f32` never double-rounds, and the result is the correctly rounded `f32`
//! root. `libm::sqrtf` (what nalgebra's `sqrt` runs on the firmware) is checked to agree too.
//!
//! `sqrt_f32`'s approximation depends only on the low 24 bits of the input (the significand and
//! the parity of the exponent), so the exhaustive run over `[1, 4)` (exponents 127 and 128)
//! covers every case of the approximation and its correction; the other exponents only shift
//! the result's exponent, which the random sample and the binade sweep check.

use estimator_core::scalar::sqrt_f32;

fn reference(x: f32) -> f32 {
    (x as f64).sqrt() as f32
}

/// Same bits, or both NaN (a NaN's sign and payload are not specified).
fn check(x: f32) {
    let got = sqrt_f32(x);
    let want = reference(x);
    if want.is_nan() {
        assert!(
            got.is_nan(),
            "sqrt_f32({x:e} = {:#010x}) = {got:e}, not NaN",
            x.to_bits()
        );
    } else {
        assert_eq!(
            got.to_bits(),
            want.to_bits(),
            "sqrt_f32({x:e} = {:#010x}) = {got:e}, not {want:e}",
            x.to_bits()
        );
    }
}

/// Every `f32` in `[1, 4)`: every significand with both exponent parities.
#[test]
fn exhaustive_over_one_to_four() {
    for b in 1.0f32.to_bits()..4.0f32.to_bits() {
        let x = f32::from_bits(b);
        check(x);
        assert_eq!(
            sqrt_f32(x).to_bits(),
            libm::sqrtf(x).to_bits(),
            "libm at {x:e}"
        );
    }
}

/// Every subnormal, of both signs (negative ones give NaN).
#[test]
fn exhaustive_subnormals() {
    for b in 1..0x0080_0000u32 {
        check(f32::from_bits(b));
        check(f32::from_bits(b | 0x8000_0000));
    }
}

/// A few thousand significands in every binade, both signs.
#[test]
fn every_exponent() {
    for e in 0..256u32 {
        for k in 0..4096u32 {
            let b = (e << 23) | (k.wrapping_mul(0x9e37_79b9) >> 9);
            check(f32::from_bits(b));
            check(f32::from_bits(b | 0x8000_0000));
        }
    }
}

/// Random bit patterns over the whole `u32` range (all exponents, signs, NaNs).
#[test]
fn random_bit_patterns() {
    let mut s = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..4_000_000 {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let x = f32::from_bits((s >> 16) as u32);
        check(x);
        if x >= 0.0 {
            assert_eq!(
                sqrt_f32(x).to_bits(),
                libm::sqrtf(x).to_bits(),
                "libm at {x:e}"
            );
        }
    }
}

/// IEEE 754's special values, bit for bit where they are numbers.
#[test]
fn special_values() {
    let same = |x: f32, want: f32| {
        assert_eq!(sqrt_f32(x).to_bits(), want.to_bits(), "sqrt_f32({x:e})");
    };
    same(0.0, 0.0);
    same(-0.0, -0.0);
    same(f32::INFINITY, f32::INFINITY);
    same(1.0, 1.0);
    same(4.0, 2.0);
    same(0.25, 0.5);
    same(f32::MAX, 1.844_674_3e19);
    same(f32::MIN_POSITIVE, 1.084_202_2e-19);
    same(f32::from_bits(1), f32::from_bits(0x1a35_04f3)); // √(2⁻¹⁴⁹) = 2^-74.5
    same(
        f32::from_bits(0x007f_ffff),
        reference(f32::from_bits(0x007f_ffff)),
    );
    for x in [
        f32::NAN,
        -f32::NAN,
        f32::from_bits(0x7f80_0001), // signalling NaN
        f32::from_bits(0xff80_0001),
        f32::NEG_INFINITY,
        -1.0,
        -f32::MIN_POSITIVE,
        -f32::from_bits(1),
        -f32::MAX,
    ] {
        assert!(sqrt_f32(x).is_nan(), "sqrt_f32({x:e}) = {}", sqrt_f32(x));
    }
    // A signalling NaN comes back quiet.
    assert_ne!(
        sqrt_f32(f32::from_bits(0x7f80_0001)).to_bits() & 0x0040_0000,
        0
    );
}

/// All 2³² inputs (a minute or two): `cargo test --release -- --ignored`.
#[test]
#[ignore]
fn exhaustive_all_bit_patterns() {
    for b in 0..=u32::MAX {
        check(f32::from_bits(b));
    }
}
