//! Owen-scrambled Sobol' points.
//!
//! The first N points of the Sobol' sequence (Sobol' 1967; direction numbers
//! of Joe & Kuo 2008, see [`super::sobol_table`]), each dimension scrambled
//! by a nested uniform scramble (Owen 1995, "Randomly permuted
//! (t,m,s)-nets and (t,s)-sequences"): bit b of the binary fraction (from
//! the most significant) is flipped by a random bit drawn for the node of
//! the binary tree that the bits above b select, independently for every
//! node, seed and dimension. Node flips come from a SplitMix64 finalizer of
//! (seed, node); tests/sampler_properties.rs checks the distribution Owen's
//! scramble implies for pairs of points. `scramble=hash` keeps Burley's
//! faster hash-based Laine–Karras approximation (B. Burley 2020,
//! "Practical hash-based Owen scrambling", JCGT 9(4)), whose pair
//! statistics are measurably off (1.7% at the top level). Scrambling keeps
//! the net structure: for N = 2^m the first two dimensions form a
//! (0, m, 2)-net.
//!
//! The nested scramble draws only the top m = ⌈log₂ N⌉ levels from the
//! tree: the first N points of each dimension lie in distinct intervals of
//! width 2^−m (a (0, m, 1)-net or part of one), so below level m every
//! point's node is its own and the flips there are independent uniform
//! bits whatever the digits they flip: the rest of the mantissa is uniform
//! (53 − m bits from the set's stream). The same distribution as
//! scrambling all 32 digits, at m node draws per coordinate instead of 32
//! (8× fewer at N = 16). The hash scramble works on 32 digits; 21
//! uniform bits complete its mantissa. Either way every coordinate is
//! uniform on [0,1).

use super::config::Config;
use super::sobol_table::JOE_KUO;
use super::{Sampler, SamplerError};
use crate::points::PointSet;
use crate::rng::{SetRng, mix64};
use rand::Rng;

/// Dimensions with tabulated direction numbers.
pub const MAX_DIM: usize = JOE_KUO.len() + 1;

const BITS: usize = 32;

/// How the digits are scrambled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scramble {
    /// Nested uniform scrambling (Owen 1995): an independent flip per tree
    /// node.
    Owen,
    /// Burley's hash-based Laine–Karras approximation (faster; its node
    /// flips are not independent).
    Hash,
}

/// Owen-scrambled Sobol' points: N ≤ 2^32 in d ≤ [`MAX_DIM`] dimensions.
#[derive(Debug, Clone)]
pub struct Sobol {
    n: usize,
    /// 32 direction numbers per dimension, v_k = m_k · 2^(32−k).
    directions: Vec<[u32; BITS]>,
    scramble: Scramble,
}

impl Sobol {
    /// The first N points in d dimensions, scrambled by `scramble`.
    ///
    /// # Errors
    /// A message if d is 0 or above [`MAX_DIM`], or N > 2^32.
    pub fn new(n: usize, dim: usize, scramble: Scramble) -> Result<Self, String> {
        if dim == 0 || dim > MAX_DIM || (n as u64) > 1 << 32 {
            return Err(format!(
                "Sobol' points need 1 <= d <= {MAX_DIM} and N <= 2^32, got d = {dim}, N = {n}"
            ));
        }
        Ok(Sobol {
            n,
            directions: (0..dim).map(direction_numbers).collect(),
            scramble,
        })
    }
}

/// Direction numbers of dimension `j` (0-based) by the recurrence
/// m_k = 2a_1 m_(k−1) ⊕ 2²a_2 m_(k−2) ⊕ … ⊕ 2^s m_(k−s) ⊕ m_(k−s)
/// (Bratley & Fox 1988, Eq. (1); Joe & Kuo 2008 §2).
fn direction_numbers(j: usize) -> [u32; BITS] {
    let mut m = [1u64; BITS];
    if j > 0 {
        let (s, a, init) = JOE_KUO[j - 1];
        let s = s as usize;
        for (k, &mk) in init.iter().enumerate() {
            m[k] = mk as u64;
        }
        for k in s..BITS {
            let mut next = m[k - s] ^ (m[k - s] << s);
            for i in 1..s {
                let a_i = (a >> (s - 1 - i)) & 1;
                if a_i == 1 {
                    next ^= m[k - i] << i;
                }
            }
            m[k] = next;
        }
    }
    std::array::from_fn(|k| (m[k] << (BITS - 1 - k)) as u32)
}

/// Burley's Laine–Karras-style hash: a bijection of u32 in which output bit
/// b depends only on input bits ≤ b (JCGT 9(4), listing 2 constants).
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Burley's approximation of the nested uniform scramble of x·2⁻³².
#[inline]
fn hash_scramble(x: u32, seed: u64) -> u32 {
    laine_karras(x.reverse_bits(), seed as u32).reverse_bits()
}

/// The nested uniform scramble of the top `levels` digits of the binary
/// fraction x·2⁻³² (Owen 1995): bit b (0 = most significant) is flipped by
/// the random bit of the tree node selected by the b bits above it, node
/// id 2^b + prefix (unique per level and prefix), drawn from SplitMix64's
/// finalizer of (seed, node). Digits below `levels` are returned as they
/// are.
#[inline]
pub fn owen_scramble(x: u32, seed: u64, levels: u32) -> u32 {
    let mut out = x;
    for b in 0..levels.min(BITS as u32) {
        let prefix = if b == 0 { 0 } else { u64::from(x >> (32 - b)) };
        let node = (1u64 << b) | prefix;
        let flip = (mix64(seed ^ mix64(node)) >> 63) as u32;
        out ^= flip << (31 - b);
    }
    out
}

pub(crate) fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    if c.n as u64 > 1 << 32 {
        return Err(c.bad_count("N <= 2^32", Some(1 << 32), None));
    }
    let scramble = match c.param("scramble") {
        "owen" => Scramble::Owen,
        "hash" => Scramble::Hash,
        _ => return Err(c.bad_param("scramble", "owen or hash")),
    };
    let sobol = Sobol::new(c.n, c.dim, scramble).map_err(|e| c.bad_param("scramble", e))?;
    Ok(Box::new(sobol))
}

impl Sampler for Sobol {
    fn dim(&self) -> usize {
        self.directions.len()
    }

    fn points_per_set(&self) -> usize {
        self.n
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let d = self.directions.len();
        let seeds: Vec<u64> = (0..d).map(|_| rng.next_u64()).collect();
        // x_i = x_(i−1) ⊕ v_0 ⊕ … ⊕ v_c with c the trailing zeros of i (the
        // bits that flip from i−1 to i), so prefix XORs give one XOR a step.
        let flips: Vec<[u32; BITS]> = self
            .directions
            .iter()
            .map(|v| {
                let mut acc = 0;
                std::array::from_fn(|k| {
                    acc ^= v[k];
                    acc
                })
            })
            .collect();
        let mut x = vec![0u32; d];
        let mut tails = TailBits::default();
        let mut coords = Vec::with_capacity(self.n * d);
        // Tree levels that hold more than one of the N points.
        let levels = (self.n as u64).next_power_of_two().trailing_zeros();
        for i in 0..self.n as u64 {
            if i > 0 {
                let c = i.trailing_zeros() as usize;
                for (xj, f) in x.iter_mut().zip(&flips) {
                    *xj ^= f[c];
                }
            }
            for (&xj, &seed) in x.iter().zip(&seeds) {
                let bits = match self.scramble {
                    Scramble::Owen => {
                        // The top `levels` scrambled digits, then 53 − levels
                        // uniform bits (module docs).
                        let top = u64::from(owen_scramble(xj, seed, levels)) >> (32 - levels);
                        (top << (53 - levels)) | (rng.next_u64() >> (11 + levels))
                    }
                    // 21 uniform bits below the 32 scrambled ones.
                    Scramble::Hash => (u64::from(hash_scramble(xj, seed)) << 21) | tails.next(rng),
                };
                // 53 bits, exact, < 1.
                coords.push(bits as f64 * (1.0 / (1u64 << 53) as f64));
            }
        }
        Ok(PointSet::new(d, coords).expect("scrambled fractions lie in [0,1)"))
    }
}

/// Hands out 21-bit uniform integers, three from each 64-bit draw.
#[derive(Default)]
struct TailBits {
    bits: u64,
    left: u32,
}

impl TailBits {
    fn next(&mut self, rng: &mut SetRng) -> u64 {
        if self.left < 21 {
            self.bits = rng.next_u64();
            self.left = 64;
        }
        let out = self.bits & ((1 << 21) - 1);
        self.bits >>= 21;
        self.left -= 21;
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_dimensions_are_van_der_corput_and_its_companion() {
        // Unscrambled dimension 0 is the van der Corput sequence; dimension 1
        // (x+1, m_k = 1) gives 1/2, 3/4, 1/4 for i = 1, 2, 3 (Bratley & Fox 1988).
        let s = Sobol::new(4, 2, Scramble::Owen).unwrap();
        let point = |i: u64, j: usize| {
            (0..32)
                .filter(|k| i >> k & 1 == 1)
                .fold(0u32, |x, k| x ^ s.directions[j][k]) as f64
                / 2f64.powi(32)
        };
        assert_eq!([point(1, 0), point(2, 0), point(3, 0)], [0.5, 0.25, 0.75]);
        assert_eq!([point(1, 1), point(2, 1), point(3, 1)], [0.5, 0.75, 0.25]);
    }

    #[test]
    fn unscrambled_points_equal_an_independent_implementation() {
        // SciPy's Sobol' generator with the same Joe–Kuo table
        // (tests/data/sobol-unscrambled-256x21.csv, its header says how it
        // was made): the first 256 points in all 21 dimensions, compared as
        // a set because SciPy enumerates them in Gray-code order. A mistyped
        // polynomial or initial value changes a dimension's points.
        let text = include_str!("../../tests/data/sobol-unscrambled-256x21.csv");
        let mut reference: Vec<Vec<u32>> = text
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(reference.len(), 256);
        let s = Sobol::new(256, MAX_DIM, Scramble::Owen).unwrap();
        let mut ours: Vec<Vec<u32>> = (0..256u64)
            .map(|i| {
                (0..MAX_DIM)
                    .map(|j| {
                        (0..32)
                            .filter(|b| i >> b & 1 == 1)
                            .fold(0u32, |x, b| x ^ s.directions[j][b])
                    })
                    .collect()
            })
            .collect();
        reference.sort_unstable();
        ours.sort_unstable();
        for (j, (r, o)) in reference.iter().zip(&ours).enumerate() {
            assert_eq!(r, o, "sorted point {j} differs from SciPy's");
        }
    }

    #[test]
    fn every_dimension_is_a_net_and_the_first_pair_a_zero_net() {
        // Each dimension alone is a (0, m, 1)-net (true for any odd m_k),
        // and dimensions 0 and 1 form a (0, m, 2)-net (Sobol' 1967: the
        // van der Corput sequence with its companion, m_k = 1 and x + 1).
        let m = 10;
        let s = Sobol::new(1 << m, MAX_DIM, Scramble::Owen).unwrap();
        let point = |i: u64, dim: usize| {
            (0..32)
                .filter(|b| i >> b & 1 == 1)
                .fold(0u32, |x, b| x ^ s.directions[dim][b])
        };
        for j in 0..MAX_DIM {
            let mut cells: Vec<u32> = (0..1u64 << m).map(|i| point(i, j) >> (32 - m)).collect();
            cells.sort_unstable();
            assert!(
                cells.iter().enumerate().all(|(i, &c)| c as usize == i),
                "dimension {j} is not a (0, {m}, 1)-net"
            );
        }
        // Every elementary interval of area 2^-m, [a/2^i, (a+1)/2^i) ×
        // [b/2^(m−i), (b+1)/2^(m−i)), holds exactly one point.
        for i in 0..=m {
            let mut cells: Vec<u64> = (0..1u64 << m)
                .map(|p| {
                    let x = u64::from(point(p, 0)) >> (32 - i);
                    let y = u64::from(point(p, 1)) >> (32 - (m - i));
                    (x << (m - i)) | y
                })
                .collect();
            cells.sort_unstable();
            assert!(
                cells.iter().enumerate().all(|(c, &v)| v == c as u64),
                "intervals 2^-{i} x 2^-{} do not hold one point each",
                m - i
            );
        }
    }

    #[test]
    fn scramble_is_nested() {
        // Output bit b (from the top) depends only on input bits above it: two
        // inputs that share their top t bits share the top t output bits.
        let owen = |x, seed| owen_scramble(x, seed, 32);
        for scramble in [owen, hash_scramble] {
            for seed in [0u64, 1, 0xdead_beef] {
                for t in 1..32 {
                    let a = 0x9e37_79b9u32;
                    let b = a ^ (1u32 << (31 - t)); // differs first at bit t from the top
                    let (sa, sb) = (scramble(a, seed), scramble(b, seed));
                    assert_eq!(sa >> (32 - t), sb >> (32 - t), "seed {seed}, t {t}");
                    assert_ne!(sa >> (31 - t), sb >> (31 - t), "bijective at bit {t}");
                }
            }
        }
    }
}
