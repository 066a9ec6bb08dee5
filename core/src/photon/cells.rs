//! Cells of a group of the photon map, as keys and hashed bit sets: which
//! cells hold a photon ([`CellBits`] of the occupied cells), and which
//! blocks of 2×2×2 cells do, each block named by its lowest cell
//! ([`CellBits::insert_blocks_of`]). Cells are twice the radius wide, so a
//! query's cells are such a block (or fewer), and one clear bit of the
//! second set says that a gather there finds nothing. Most gathers of
//! most shipped scenes find nothing (640×360, 16 spp: 99.3 % of
//! focal-spot's, 95 % of optical-bench's, 79 % of cubes', 62 % of
//! primitives'), and walking their eight cells to learn it cost about as
//! much as a gather that finds photons.

/// A cell's key: its integer coordinates.
pub(super) type Key = [i64; 3];

/// A cheap hash of a cell's key, for the cells' table and the bit sets.
#[inline]
pub(super) fn cell_hash(k: Key) -> u64 {
    hash_mix(hash_term(0, k[0]) ^ hash_term(1, k[1]) ^ hash_term(2, k[2]))
}

/// Axis `c`'s share of [`cell_hash`] for the coordinate `k`.
#[inline(always)]
pub(super) fn hash_term(c: usize, k: i64) -> u64 {
    const MUL: [u64; 3] = [0x9e37_79b9_7f4a_7c15, 0xc2b2_ae3d_27d4_eb4f, 0x1656_67b1_9e37_79f9];
    (k as u64).wrapping_mul(MUL[c])
}

/// [`cell_hash`]'s last step, on the axes' shares combined.
#[inline(always)]
pub(super) fn hash_mix(h: u64) -> u64 {
    h ^ (h >> 29)
}

/// A set of cells as `2^log2` bits indexed by the top bits of their hash:
/// a clear bit means the cell is not in the set (a set bit may be
/// another cell's).
#[derive(Clone, Debug)]
pub(super) struct CellBits {
    log2: u32,
    words: Vec<u64>,
}

impl CellBits {
    /// An empty set of `2^log2` bits (`log2` from 6 to 63).
    pub(super) fn new(log2: u32) -> Self {
        CellBits {
            log2,
            words: vec![0; 1 << (log2 - 6)],
        }
    }

    /// Its size, as a power of two.
    pub(super) fn log2(&self) -> u32 {
        self.log2
    }

    /// The word and bit of the cell of hash `h`.
    #[inline(always)]
    fn bit(&self, h: u64) -> (usize, u64) {
        let b = (h >> (64 - self.log2)) as usize;
        (b >> 6, 1u64 << (b & 63))
    }

    pub(super) fn insert(&mut self, k: Key) {
        let (w, b) = self.bit(cell_hash(k));
        self.words[w] |= b;
    }

    /// Inserts the blocks of 2×2×2 cells that hold cell `k`: the cells
    /// `k − d` for `d` in `{0, 1}³` (saturating at the low end of `i64`).
    pub(super) fn insert_blocks_of(&mut self, k: Key) {
        for d in 0..8 {
            let at = |c: usize| k[c].saturating_sub((d >> c) & 1);
            self.insert([at(0), at(1), at(2)]);
        }
    }

    /// Whether the cell of hash `h` may be in the set.
    #[inline(always)]
    pub(super) fn may_hold(&self, h: u64) -> bool {
        let (w, b) = self.bit(h);
        self.words[w] & b != 0
    }
}

/// Whether the cells `a ..= b` (with `a ≤ b`) lie in the block of 2×2×2
/// cells whose lowest cell is `a`.
#[inline(always)]
pub(super) fn one_block(a: Key, b: Key) -> bool {
    (0..3).all(|c| b[c].wrapping_sub(a[c]) as u64 <= 1)
}

/// The size of a group's set of cells near photons for `cells` occupied
/// cells: about 32 bits a cell (each marks up to 8 blocks), at least 2^18
/// and at most 2^24 (2 MB).
pub(super) fn reach_log2(cells: usize) -> u32 {
    let want = (cells.max(1) as u64 * 32).next_power_of_two().trailing_zeros();
    want.clamp(18, 24)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocks that hold a cell are in the set, and most others are not.
    #[test]
    fn the_blocks_of_a_cell_are_in_the_set() {
        let mut s = CellBits::new(20);
        let k = [5, -7, 1 << 40];
        s.insert_blocks_of(k);
        let mut other_clear = 0;
        for d in -2i64..=2 {
            for e in -2i64..=2 {
                for f in -2i64..=2 {
                    let a = [k[0] + d, k[1] + e, k[2] + f];
                    let holds = (-1..=0).contains(&d) && (-1..=0).contains(&e) && (-1..=0).contains(&f);
                    if holds {
                        assert!(s.may_hold(cell_hash(a)), "{a:?}");
                    } else if !s.may_hold(cell_hash(a)) {
                        other_clear += 1;
                    }
                }
            }
        }
        assert!(other_clear > 110, "{other_clear} of 117 other blocks are clear");
        let mut edge = CellBits::new(18);
        edge.insert_blocks_of([i64::MIN, i64::MAX, 0]);
        assert!(edge.may_hold(cell_hash([i64::MIN, i64::MAX - 1, -1])));
        assert!(one_block([0, 0, 0], [1, 1, 0]));
        assert!(!one_block([0, 0, 0], [2, 0, 0]));
        assert!(!one_block([i64::MIN, 0, 0], [i64::MAX, 0, 0]));
        assert_eq!((reach_log2(0), reach_log2(5000), reach_log2(1 << 30)), (18, 18, 24));
    }
}
