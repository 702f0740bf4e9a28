//! Discrete Fourier transform of any length.
//!
//! Convention: `X[k] = sum_n x[n] exp(-2 pi i k n / N)` (forward, no
//! scaling); the inverse divides by `N`, so `ifft(fft(x)) == x` up to
//! rounding.
//!
//! The transforms are rustfft's (mixed radix for lengths with small
//! factors, Rader's and Bluestein's algorithms otherwise), built without
//! its run-time SIMD dispatch, so that the same input gives the same bits
//! on every x86-64 or ARM machine. A [`FftPlan`] keeps the planned
//! transform for repeated transforms of one length, as Welch averaging
//! needs.
//!
//! ```
//! use frf::fft::{fft, ifft};
//! use frf::Complex64;
//!
//! // A unit impulse at n = 1 has X[k] = exp(-2 pi i k / N).
//! let n = 6;
//! let mut x = vec![Complex64::new(0.0, 0.0); n];
//! x[1] = Complex64::new(1.0, 0.0);
//! let big_x = fft(&x);
//! let expected = Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * 2.0 / 6.0);
//! assert!((big_x[2] - expected).norm() < 1e-12);
//! let back = ifft(&big_x);
//! assert!((back[1] - x[1]).norm() < 1e-12);
//! ```

use num_complex::Complex64;
use std::sync::Arc;

/// A precomputed transform for one length `n`.
///
/// ```
/// use frf::fft::FftPlan;
/// use frf::Complex64;
///
/// let plan = FftPlan::new(5);
/// let mut x = vec![Complex64::new(1.0, 0.0); 5];
/// plan.forward(&mut x);
/// // A constant has all its energy at k = 0.
/// assert!((x[0] - Complex64::new(5.0, 0.0)).norm() < 1e-12);
/// assert!(x[1..].iter().all(|z| z.norm() < 1e-12));
/// ```
#[derive(Clone)]
pub struct FftPlan {
    n: usize,
    kind: Kind,
}

impl std::fmt::Debug for FftPlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FftPlan").field("n", &self.n).finish()
    }
}

#[derive(Clone)]
enum Kind {
    /// Length 0 or 1: the transform is the identity.
    Trivial,
    Planned(Arc<dyn rustfft::Fft<f64>>),
    /// The textbook transforms the planner replaced, kept to check it.
    #[cfg(test)]
    Reference(reference::Plan),
}

impl FftPlan {
    /// A plan for transforms of length `n` (any `n`, including 0 and 1).
    pub fn new(n: usize) -> FftPlan {
        #[cfg(test)]
        if reference::ACTIVE.with(|a| a.get()) && n > 1 {
            return FftPlan {
                n,
                kind: Kind::Reference(reference::Plan::new(n)),
            };
        }
        let kind = if n <= 1 {
            Kind::Trivial
        } else {
            Kind::Planned(rustfft::FftPlanner::new().plan_fft_forward(n))
        };
        FftPlan { n, kind }
    }

    /// The transform length.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True for the length-0 plan.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// In-place forward transform (no scaling).
    ///
    /// # Panics
    /// If `x.len()` differs from the plan's length (a programming error,
    /// not a data error).
    pub fn forward(&self, x: &mut [Complex64]) {
        assert_eq!(x.len(), self.n, "FftPlan: length mismatch");
        match &self.kind {
            Kind::Trivial => {}
            Kind::Planned(f) => f.process(x),
            #[cfg(test)]
            Kind::Reference(r) => r.forward(x),
        }
    }

    /// In-place inverse transform, scaled by `1 / n`.
    ///
    /// # Panics
    /// If `x.len()` differs from the plan's length.
    pub fn inverse(&self, x: &mut [Complex64]) {
        for z in x.iter_mut() {
            *z = z.conj();
        }
        self.forward(x);
        let scale = if self.n == 0 {
            1.0
        } else {
            1.0 / self.n as f64
        };
        for z in x.iter_mut() {
            *z = z.conj() * scale;
        }
    }
}

/// Forward DFT of `x` (any length), returned as a new vector.
pub fn fft(x: &[Complex64]) -> Vec<Complex64> {
    let mut out = x.to_vec();
    FftPlan::new(x.len()).forward(&mut out);
    out
}

/// Inverse DFT of `x` (any length), scaled by `1 / N`.
pub fn ifft(x: &[Complex64]) -> Vec<Complex64> {
    let mut out = x.to_vec();
    FftPlan::new(x.len()).inverse(&mut out);
    out
}

/// Forward DFT of a real sequence.
///
/// ```
/// let x = [1.0, 2.0, 3.0];
/// let big_x = frf::fft::fft_real(&x);
/// assert!((big_x[0].re - 6.0).abs() < 1e-12);
/// ```
pub fn fft_real(x: &[f64]) -> Vec<Complex64> {
    let c: Vec<Complex64> = x.iter().map(|&v| Complex64::new(v, 0.0)).collect();
    fft(&c)
}

/// The radix-2 and Bluestein transforms this crate used before rustfft:
/// a second implementation to check the planner's against, and the H1
/// estimates against the ones they gave (`ACTIVE` switches
/// [`FftPlan::new`] to them on the current thread).
#[cfg(test)]
pub(crate) mod reference {
    use num_complex::Complex64;
    use std::f64::consts::PI;

    thread_local! {
        pub(crate) static ACTIVE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    }

    /// Runs `f` with every plan of this thread built from these transforms.
    pub(crate) fn with<T>(f: impl FnOnce() -> T) -> T {
        ACTIVE.with(|a| a.set(true));
        let out = f();
        ACTIVE.with(|a| a.set(false));
        out
    }

    #[derive(Clone, Debug)]
    pub(crate) enum Plan {
        Radix2(Radix2),
        Bluestein(Box<Bluestein>),
    }

    impl Plan {
        pub(crate) fn new(n: usize) -> Plan {
            if n.is_power_of_two() {
                Plan::Radix2(Radix2::new(n))
            } else {
                Plan::Bluestein(Box::new(Bluestein::new(n)))
            }
        }

        pub(crate) fn forward(&self, x: &mut [Complex64]) {
            match self {
                Plan::Radix2(r) => r.forward(x),
                Plan::Bluestein(b) => b.forward(x),
            }
        }
    }

    /// Radix-2 tables for a power-of-two length.
    #[derive(Clone, Debug)]
    pub(crate) struct Radix2 {
        /// `exp(-2 pi i k / n)` for `k < n / 2`, each computed directly (not by
        /// recurrence) so the error does not grow with `k`.
        twiddles: Vec<Complex64>,
        /// Bit-reversal permutation as swap pairs `(i, j)` with `i < j`.
        swaps: Vec<(usize, usize)>,
    }

    /// Bluestein tables for a length that is not a power of two.
    #[derive(Clone, Debug)]
    pub(crate) struct Bluestein {
        /// `exp(-i pi k^2 / n)` for `k < n`.
        chirp: Vec<Complex64>,
        /// Forward transform (length `m`) of the conjugate chirp, wrapped
        /// around so the circular convolution equals the linear one.
        kernel: Vec<Complex64>,
        /// Power-of-two plan of length `m >= 2n - 1`.
        inner: Radix2,
    }

    impl Radix2 {
        fn new(n: usize) -> Radix2 {
            debug_assert!(n.is_power_of_two() && n >= 2);
            let twiddles = (0..n / 2)
                .map(|k| Complex64::from_polar(1.0, -2.0 * PI * k as f64 / n as f64))
                .collect();
            let bits = n.trailing_zeros();
            let swaps = (0..n)
                .filter_map(|i| {
                    let j = i.reverse_bits() >> (usize::BITS - bits);
                    (i < j).then_some((i, j))
                })
                .collect();
            Radix2 { twiddles, swaps }
        }

        /// In-place forward transform; `x.len()` must be the plan's length.
        fn forward(&self, x: &mut [Complex64]) {
            let n = x.len();
            for &(i, j) in &self.swaps {
                x.swap(i, j);
            }
            let mut len = 2;
            while len <= n {
                let half = len / 2;
                // Twiddle for butterfly j of a block of this length is
                // exp(-2 pi i j / len) = twiddles[j * n / len].
                let stride = n / len;
                for block in x.chunks_exact_mut(len) {
                    let (lo, hi) = block.split_at_mut(half);
                    for (j, (a, b)) in lo.iter_mut().zip(hi.iter_mut()).enumerate() {
                        let t = *b * self.twiddles[j * stride];
                        *b = *a - t;
                        *a += t;
                    }
                }
                len *= 2;
            }
        }
    }

    impl Bluestein {
        fn new(n: usize) -> Bluestein {
            let m = (2 * n - 1).next_power_of_two();
            let inner = Radix2::new(m);
            // k^2 mod 2n keeps the angle pi k^2 / n small and exact in
            // floating point even when k^2 itself would lose precision.
            let two_n = 2 * n as u128;
            let chirp: Vec<Complex64> = (0..n)
                .map(|k| {
                    let k2 = (k as u128 * k as u128) % two_n;
                    Complex64::from_polar(1.0, -PI * k2 as f64 / n as f64)
                })
                .collect();
            let mut kernel = vec![Complex64::new(0.0, 0.0); m];
            kernel[0] = chirp[0].conj();
            for k in 1..n {
                kernel[k] = chirp[k].conj();
                kernel[m - k] = chirp[k].conj();
            }
            inner.forward(&mut kernel);
            Bluestein {
                chirp,
                kernel,
                inner,
            }
        }

        fn forward(&self, x: &mut [Complex64]) {
            let n = x.len();
            let m = self.kernel.len();
            let mut a = vec![Complex64::new(0.0, 0.0); m];
            for k in 0..n {
                a[k] = x[k] * self.chirp[k];
            }
            self.inner.forward(&mut a);
            for (ak, bk) in a.iter_mut().zip(&self.kernel) {
                // Conjugate now so that the inverse transform below can reuse
                // the forward one: ifft(z) = conj(fft(conj(z))) / m.
                *ak = (*ak * *bk).conj();
            }
            self.inner.forward(&mut a);
            let scale = 1.0 / m as f64;
            for k in 0..n {
                x[k] = a[k].conj() * scale * self.chirp[k];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The O(n^2) definition, with the angle reduced as (k n mod N) so the
    /// reference itself stays accurate for N = 1000 and 1024.
    fn naive_dft(x: &[Complex64]) -> Vec<Complex64> {
        let n = x.len();
        (0..n)
            .map(|k| {
                (0..n)
                    .map(|j| {
                        let r = (k * j) % n;
                        x[j] * Complex64::from_polar(1.0, -2.0 * PI * r as f64 / n as f64)
                    })
                    .sum()
            })
            .collect()
    }

    /// Deterministic test signal: xorshift64 values in [-1, 1).
    fn signal(n: usize, seed: u64) -> Vec<Complex64> {
        let mut s = seed;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        (0..n).map(|_| Complex64::new(next(), next())).collect()
    }

    #[test]
    fn matches_naive_dft() {
        // Tolerance: max |FFT - DFT| <= 1e-12 * sum |x|. Both errors are
        // O(eps log N) and O(eps N) relative to sum |x|; for N <= 1024
        // that is below 1e-12 with margin, while a wrong twiddle or index
        // gives errors of order 1.
        for &n in &[1usize, 2, 3, 5, 8, 10, 12, 17, 1000, 1024] {
            let x = signal(n, 0x9e37_79b9_7f4a_7c15 ^ n as u64);
            let fast = fft(&x);
            let slow = naive_dft(&x);
            let scale: f64 = x.iter().map(|z| z.norm()).sum();
            let err = fast
                .iter()
                .zip(&slow)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            assert!(err <= 1e-12 * scale, "n = {n}: error {err:e}");
        }
    }

    #[test]
    fn inverse_round_trip() {
        for &n in &[1usize, 2, 3, 8, 10, 1000, 1024] {
            let x = signal(n, 7 + n as u64);
            let back = ifft(&fft(&x));
            let err = x
                .iter()
                .zip(&back)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            assert!(err < 1e-13, "n = {n}: error {err:e}");
        }
    }

    #[test]
    fn empty_and_single() {
        assert!(fft(&[]).is_empty());
        let one = [Complex64::new(2.5, -1.0)];
        assert_eq!(fft(&one), one.to_vec());
    }

    #[test]
    fn plan_is_reusable() {
        // A plan must give the same answer on every call (no state kept
        // between transforms), for both algorithms.
        for &n in &[12usize, 16] {
            let plan = FftPlan::new(n);
            let x = signal(n, 3);
            let mut a = x.clone();
            plan.forward(&mut a);
            let mut b = x.clone();
            plan.forward(&mut b);
            assert_eq!(a, b);
        }
    }
}
