//! Decoding a fuzz input into values, and the [`Encoder`] that writes an input decoding to
//! chosen values (for the regression files).
//!
//! Every value is read one byte at a time from an [`arbitrary::Unstructured`] (an exhausted
//! input reads as zeros), so that an input can be written by hand: a number is a tag byte and
//! its payload. A real number is drawn from one of several sources, so that the fuzzer reaches
//! both deep, well-conditioned states and the edges:
//!
//! | tag % 8 | value |
//! |---|---|
//! | 0, 1, 2, 7 | "reasonable": a 16-bit fraction in `[−1, 1]` times a scale `10⁻³ … 10⁴` |
//! | 3 | a small multiple of ¼ |
//! | 4 | a special value (zero, ±1, subnormals, huge, ±∞, NaN, …) |
//! | 5 | a decimal `m·10ᵉ`, `e ∈ [−45, 44]` |
//! | 6 | a raw bit pattern of the scalar type |

use arbitrary::Unstructured;
use estimator_core::nalgebra::{Matrix3, Vector2, Vector3};
use estimator_core::Real;

/// The scalar types the targets run in: `f32` and `f64`.
pub trait Scalar: Real + core::fmt::LowerExp + core::fmt::Display {
    /// `"f32"` or `"f64"`.
    const NAME: &'static str;
    /// A raw bit pattern of the type's width, little-endian.
    fn raw(input: &mut Input<'_>) -> Self;
    /// The bytes [`Scalar::raw`] reads back as `self`.
    fn raw_bytes(self) -> Vec<u8>;
}

impl Scalar for f32 {
    const NAME: &'static str = "f32";
    fn raw(input: &mut Input<'_>) -> Self {
        f32::from_bits(input.u32())
    }
    fn raw_bytes(self) -> Vec<u8> {
        self.to_bits().to_le_bytes().to_vec()
    }
}

impl Scalar for f64 {
    const NAME: &'static str = "f64";
    fn raw(input: &mut Input<'_>) -> Self {
        f64::from_bits(input.u64())
    }
    fn raw_bytes(self) -> Vec<u8> {
        self.to_bits().to_le_bytes().to_vec()
    }
}

const SCALES: [f64; 8] = [1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0, 1e3, 1e4];

const SPECIALS: [f64; 40] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    0.5,
    2.0,
    core::f64::consts::PI,
    -core::f64::consts::PI,
    core::f64::consts::TAU,
    9.81,
    -9.81,
    1e-3,
    1e-6,
    1e-9,
    1e-12,
    1e-20,
    1e-30,
    1e-38,
    1.175_494_4e-38,
    1e-45,
    1e-155,
    1e-300,
    5e-324,
    1e6,
    1e10,
    1e15,
    1e20,
    1e30,
    1e38,
    3.4e38,
    1e155,
    1e200,
    1e300,
    f64::MAX,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NAN,
    1.192_092_9e-7,
    f64::EPSILON,
    -1e20,
];

/// The tag of a raw real (see the module docs).
const RAW: u8 = 6;
/// A byte at or above this makes [`Input::sigma`], [`Input::dt`] and friends read a general
/// real instead of their usual range.
const GENERAL: u8 = 224;

/// A fuzz input being decoded.
pub struct Input<'a> {
    u: Unstructured<'a>,
}

impl<'a> Input<'a> {
    /// Decodes `data` from its start.
    #[must_use]
    pub fn new(data: &'a [u8]) -> Self {
        Self {
            u: Unstructured::new(data),
        }
    }

    /// `true` when every byte has been read.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.u.is_empty()
    }

    /// The next byte (0 once the input is exhausted).
    pub fn byte(&mut self) -> u8 {
        self.u.arbitrary::<u8>().unwrap_or(0)
    }

    /// A little-endian `u16`.
    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.byte(), self.byte()])
    }

    /// A little-endian `u32`.
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.byte(), self.byte(), self.byte(), self.byte()])
    }

    /// A little-endian `u64`.
    pub fn u64(&mut self) -> u64 {
        u64::from(self.u32()) | (u64::from(self.u32()) << 32)
    }

    /// `byte % n` (`n` at most 256, at least 1).
    pub fn pick(&mut self, n: usize) -> usize {
        usize::from(self.byte()) % n.max(1)
    }

    /// `true` with probability `k/256`.
    pub fn chance(&mut self, k: u8) -> bool {
        self.byte() < k
    }

    /// Up to `max` bytes taken as they are (the count is a `u16`).
    pub fn bytes(&mut self, max: usize) -> &'a [u8] {
        let n = usize::from(self.u16()) % (max + 1);
        self.u.bytes(n.min(self.u.len())).unwrap_or(&[])
    }

    /// A real number from any of the sources of the module docs.
    pub fn real<T: Scalar>(&mut self) -> T {
        match self.byte() % 8 {
            3 => T::lit(f64::from(self.byte() as i8) * 0.25),
            4 => T::lit(SPECIALS[self.pick(SPECIALS.len())]),
            5 => {
                let m = f64::from(self.u16() as i16) / 1000.0;
                let e = i32::from(self.byte() % 90) - 45;
                T::lit(m * 10f64.powi(e))
            }
            RAW => T::raw(self),
            _ => self.moderate(),
        }
    }

    /// A finite number of magnitude at most `10⁴`.
    pub fn moderate<T: Scalar>(&mut self) -> T {
        let scale = SCALES[self.pick(SCALES.len())];
        let fraction = f64::from(self.u16()) / 32_767.5 - 1.0;
        T::lit(fraction * scale)
    }

    /// `10^(lo + (hi − lo)·u)` for a 16-bit fraction `u`, or a general real after a byte at or
    /// above [`GENERAL`].
    fn log_uniform<T: Scalar>(&mut self, lo: f64, hi: f64) -> T {
        if self.byte() >= GENERAL {
            return self.real();
        }
        let u = f64::from(self.u16()) / 65_535.0;
        T::lit(10f64.powf(lo + (hi - lo) * u))
    }

    /// A standard deviation: mostly in `[10⁻⁶, 10³]`.
    pub fn sigma<T: Scalar>(&mut self) -> T {
        self.log_uniform(-6.0, 3.0)
    }

    /// A time step, s: mostly in `[10⁻⁴, 10⁻¹]`.
    pub fn dt<T: Scalar>(&mut self) -> T {
        self.log_uniform(-4.0, -1.0)
    }

    /// Three reals, or (mode 2) three moderate numbers, or (mode 3) zero.
    pub fn vec3<T: Scalar>(&mut self) -> Vector3<T> {
        match self.byte() % 4 {
            2 => Vector3::new(self.moderate(), self.moderate(), self.moderate()),
            3 => Vector3::zeros(),
            _ => Vector3::new(self.real(), self.real(), self.real()),
        }
    }

    /// Three moderate numbers.
    pub fn moderate3<T: Scalar>(&mut self) -> Vector3<T> {
        Vector3::new(self.moderate(), self.moderate(), self.moderate())
    }

    /// Two reals.
    pub fn vec2<T: Scalar>(&mut self) -> Vector2<T> {
        Vector2::new(self.real(), self.real())
    }

    /// Nine reals, column by column.
    pub fn mat3<T: Scalar>(&mut self) -> Matrix3<T> {
        Matrix3::from_fn(|_, _| self.real())
    }
}

/// Writes an input that [`Input`] decodes to chosen values, call for call.
#[derive(Clone, Debug, Default)]
pub struct Encoder {
    /// The input so far.
    pub bytes: Vec<u8>,
}

impl Encoder {
    /// An empty input.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// One byte, read back by [`Input::byte`] (and [`Input::pick`], [`Input::chance`]).
    pub fn byte(&mut self, b: u8) -> &mut Self {
        self.bytes.push(b);
        self
    }

    /// A little-endian `u16`.
    pub fn u16(&mut self, x: u16) -> &mut Self {
        self.bytes.extend_from_slice(&x.to_le_bytes());
        self
    }

    /// A little-endian `u64`.
    pub fn u64(&mut self, x: u64) -> &mut Self {
        self.bytes.extend_from_slice(&x.to_le_bytes());
        self
    }

    /// Exactly `x`, read back by [`Input::real`].
    pub fn real<T: Scalar>(&mut self, x: T) -> &mut Self {
        self.bytes.push(RAW);
        self.bytes.extend(x.raw_bytes());
        self
    }

    /// Exactly `x`, read back by [`Input::sigma`] or [`Input::dt`].
    pub fn general<T: Scalar>(&mut self, x: T) -> &mut Self {
        self.bytes.push(0xff);
        self.real(x)
    }

    /// Exactly `v`, read back by [`Input::vec3`].
    pub fn vec3<T: Scalar>(&mut self, v: [T; 3]) -> &mut Self {
        self.bytes.push(0);
        for x in v {
            self.real(x);
        }
        self
    }
}
