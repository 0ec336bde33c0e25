//! The frequency box B = {k ∈ Z^d : |k|∞ ≤ h} on which spectra are held.

/// Integer frequencies k with every |k_j| ≤ `half`, in d dimensions, stored
/// with k_0 varying fastest (index Σ_j (k_j + h)·(2h+1)^j).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrequencyBox {
    /// Dimension d.
    pub dim: usize,
    /// h: the largest |k_j|.
    pub half: usize,
}

impl FrequencyBox {
    /// The box |k|∞ < K/2 of the command line's `--res K` (h = ⌊(K−1)/2⌋).
    pub fn from_resolution(dim: usize, res: usize) -> Self {
        FrequencyBox {
            dim,
            half: res.saturating_sub(1) / 2,
        }
    }

    /// Frequencies per axis, 2h+1.
    pub fn side(&self) -> usize {
        2 * self.half + 1
    }

    /// Number of frequencies, (2h+1)^d.
    ///
    /// # Panics
    /// When (2h+1)^d overflows; boxes from user input pass through
    /// [`Self::checked_len`] (and the memory check) first.
    pub fn len(&self) -> usize {
        self.checked_len()
            .expect("frequency boxes are size-checked before use")
    }

    /// (2h+1)^d, or `None` when it overflows.
    pub fn checked_len(&self) -> Option<usize> {
        (2usize.checked_mul(self.half)?.checked_add(1)?).checked_pow(self.dim as u32)
    }

    /// Never empty (h = 0 still holds k = 0).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Writes the frequency at `index` into `k`.
    pub fn frequency(&self, index: usize, k: &mut [i64]) {
        let side = self.side();
        let mut rest = index;
        for kj in k.iter_mut() {
            *kj = (rest % side) as i64 - self.half as i64;
            rest /= side;
        }
    }

    /// The index of the zero frequency.
    pub fn zero_index(&self) -> usize {
        (0..self.dim).fold(0, |acc, _| acc * self.side() + self.half)
    }
}
