//! One level's photons for fixed-radius queries: the blocks of every
//! occupied cell side by side in one array, cells in key order (so the
//! cells next to each other along the last axis are next to each other in
//! memory), found by the cell's place in the occupied cells' box where
//! that box is small ([`Dense`]), else through a small open-addressed table
//! of the occupied cells. A query touches one entry of the box (or one or
//! two table slots) and the cell's contiguous blocks, where a hash map of
//! per-cell vectors cost a miss for the bucket, one for the vector's header
//! and one for its blocks (issue 29.3: half of the gather's time in
//! rim-lens was those misses, `perf`). Photons are merged in by counting
//! their cells, not sorting them ([`Grid::add`]).

use super::cells::{Key, cell_hash};
use super::{BLOCK, Block};

/// An occupied cell: its key and its blocks, `blocks[start..start + len]`
/// (`len == 0`: an empty slot of the table).
#[derive(Clone, Copy, Debug)]
struct Slot {
    key: Key,
    start: u32,
    len: u32,
}

const EMPTY: Slot = Slot {
    key: [0; 3],
    start: 0,
    len: 0,
};

/// One photon as a cell stores it: its cell, its position from the cell's
/// low corner, its arrival direction, its power (over its pass's disc) and
/// its pass's squared radius.
#[derive(Clone, Copy, Debug)]
pub(super) struct Entry {
    pub key: Key,
    pub rel: [f32; 3],
    pub dir: [f32; 3],
    pub power: [f32; 3],
    pub r2: f32,
}

/// The cells of one level (see the module's documentation).
#[derive(Clone, Debug, Default)]
pub(super) struct Grid {
    blocks: Vec<Block>,
    /// The occupied cells, in key order (their blocks side by side in
    /// `blocks`, in the same order).
    cells: Vec<Slot>,
    find: Find,
}

/// How a cell's blocks are found from its key.
#[derive(Clone, Debug)]
enum Find {
    /// An open-addressed table of the occupied cells, a power of two long,
    /// at most half full (empty before any photon).
    Hashed(Vec<Slot>),
    /// Where the occupied cells' box is small enough ([`DENSE_PER_CELL`]):
    /// every cell of the box by its place in it.
    Dense(Dense),
}

impl Default for Find {
    fn default() -> Find {
        Find::Hashed(Vec::new())
    }
}

/// Cells of the box a [`Find::Dense`] may hold for each occupied one (a
/// box cell costs 4 bytes where a hashed cell costs 64, two 32-byte slots:
/// at most this the dense index is no larger than the table), or
/// [`DENSE_ANYWAY`] in all (1 MiB). Past both the table is used: a few
/// stray photons can stretch the box over millions of empty cells
/// (focal-spot: 1 819 cells in a box of 8.5 M), and filling an index that
/// large at each merge cost more than its lookups saved.
const DENSE_PER_CELL: usize = 16;
const DENSE_ANYWAY: usize = 1 << 18;

/// Every cell of the box `lo ..= lo + dims − 1` by its place in it (`k`
/// fastest, then `j`, then `i`: key order): cell `c`'s blocks are
/// `blocks[start[c]..start[c + 1]]`, empty for a cell with no photon. One
/// load finds a cell, with no key to compare and no probing, and the cells
/// next to each other along the last axis share a cache line (the hashed
/// table's slot loads were a quarter of rim-lens's gather, `perf`).
#[derive(Clone, Debug)]
struct Dense {
    lo: Key,
    dims: [u64; 3],
    start: Vec<u32>,
}

impl Dense {
    /// The place of cell `k` in the box, or `None` outside it.
    #[inline(always)]
    fn place(&self, k: Key) -> Option<usize> {
        let off = [0, 1, 2].map(|c| k[c].wrapping_sub(self.lo[c]) as u64);
        if (0..3).any(|c| off[c] >= self.dims[c]) {
            return None;
        }
        Some(((off[0] * self.dims[1] + off[1]) * self.dims[2] + off[2]) as usize)
    }

    /// The dense index of the key-ordered `cells` (blocks side by side in
    /// that order, `total` in all), or `None` when their box holds more
    /// than [`DENSE_PER_CELL`] cells for each of them (and more than
    /// [`DENSE_ANYWAY`]).
    fn of(cells: &[Slot], total: usize) -> Option<Dense> {
        let (first, _) = cells.split_first()?;
        let (mut lo, mut hi) = (first.key, first.key);
        for c in cells {
            for a in 0..3 {
                (lo[a], hi[a]) = (lo[a].min(c.key[a]), hi[a].max(c.key[a]));
            }
        }
        let most = (cells.len() * DENSE_PER_CELL).max(DENSE_ANYWAY) as u64;
        let mut dims = [0u64; 3];
        let mut size = 1u64;
        for a in 0..3 {
            dims[a] = (hi[a] as i128 - lo[a] as i128 + 1).try_into().ok()?;
            size = size.checked_mul(dims[a]).filter(|&n| n <= most)?;
        }
        let mut d = Dense {
            lo,
            dims,
            start: vec![0; size as usize + 1],
        };
        // Each cell's entry, and those of the empty cells before it, hold
        // where its blocks start; the entries past the last, the end.
        let mut next = 0;
        for c in cells {
            let place = d.place(c.key)?;
            d.start[next..=place].fill(c.start);
            next = place + 1;
        }
        d.start[next..].fill(total as u32);
        Some(d)
    }
}

impl Grid {
    /// The blocks of cell `k` of hash `h` ([`cell_hash`]; none when it
    /// holds no photon).
    #[inline(always)]
    pub(super) fn get(&self, k: Key, h: u64) -> Option<&[Block]> {
        let table = match &self.find {
            Find::Dense(d) => {
                let c = d.place(k)?;
                let (from, to) = (d.start[c] as usize, d.start[c + 1] as usize);
                return self.blocks.get(from..to).filter(|b| !b.is_empty());
            }
            Find::Hashed(table) => table,
        };
        let mask = table.len().checked_sub(1)?;
        let mut i = h as usize & mask;
        loop {
            let s = &table[i];
            if s.len == 0 {
                return None;
            }
            if s.key == k {
                let start = s.start as usize;
                return self.blocks.get(start..start + s.len as usize);
            }
            i = (i + 1) & mask;
        }
    }

    /// The occupied cells' keys, in key order.
    pub(super) fn keys(&self) -> impl Iterator<Item = Key> + '_ {
        self.cells.iter().map(|s| s.key)
    }

    /// Adds photons, each after those already in its cell and in the order
    /// given (so a cell's blocks are what inserting them one by one gives:
    /// every block full but the last). Returns the keys of the cells that
    /// held no photon before, in order.
    ///
    /// The cells are laid out first (old and new keys merged in key order),
    /// then every photon is written straight into its lane, in the order
    /// given: reading the photons in their cells' order instead missed the
    /// cache on every photon (half of the merge's time, `perf annotate`).
    pub(super) fn add(&mut self, new: &[Entry]) -> Vec<Key> {
        let counted = Counted::of(new);
        let old = std::mem::take(&mut self.cells);
        let mut cells = Vec::with_capacity(old.len() + counted.keys.len());
        // The lane (counted over the blocks) of each new cell's next photon.
        let mut next = vec![0usize; counted.keys.len()];
        let mut opened = Vec::new();
        // The old cells' blocks: where they are, where they go, how many.
        let mut copies = Vec::with_capacity(old.len());
        let mut total = 0;
        let (mut a, mut b) = (0, 0);
        while a < old.len() || b < counted.ranked.len() {
            let from_old = old.get(a).map(|s| s.key);
            let from_new = counted.ranked.get(b).map(|&c| counted.keys[c as usize]);
            let key = match (from_old, from_new) {
                (Some(x), Some(y)) => x.min(y),
                (x, y) => x.or(y).unwrap_or_default(),
            };
            let mut photons = 0;
            if from_old == Some(key) {
                let s = old[a];
                let last = &self.blocks[(s.start + s.len - 1) as usize];
                photons = (s.len as usize - 1) * BLOCK + last.len;
                copies.push((s.start as usize, total, s.len as usize));
                a += 1;
            } else {
                opened.push(key);
            }
            if from_new == Some(key) {
                let c = counted.ranked[b] as usize;
                next[c] = total * BLOCK + photons;
                photons += counted.counts[c] as usize;
                b += 1;
            }
            let len = photons.div_ceil(BLOCK);
            cells.push(Slot {
                key,
                start: total as u32,
                len: len as u32,
            });
            total += len;
        }
        let mut blocks = vec![Block::EMPTY; total];
        for (from, to, len) in copies {
            blocks[to..to + len].clone_from_slice(&self.blocks[from..from + len]);
        }
        for (e, &c) in new.iter().zip(&counted.cell_of) {
            let lane = next[c as usize];
            next[c as usize] += 1;
            set_lane(&mut blocks[lane / BLOCK], lane % BLOCK, e);
        }
        self.blocks = blocks;
        self.find = match Dense::of(&cells, total) {
            Some(d) => Find::Dense(d),
            None => Find::Hashed(table_of(&cells)),
        };
        self.cells = cells;
        opened
    }
}

/// The distinct keys of photons, numbered in the order first met: each
/// photon's number, each number's photons, and the numbers in key order.
/// Counted, not sorted: only the distinct keys (a few photons' worth a
/// cell) are sorted, where sorting every photon's index by `(key, index)`
/// was 12 % of focal-spot's frame instructions (callgrind).
struct Counted {
    keys: Vec<Key>,
    counts: Vec<u32>,
    cell_of: Vec<u32>,
    ranked: Vec<u32>,
}

impl Counted {
    fn of(new: &[Entry]) -> Counted {
        const FREE: u32 = u32::MAX;
        let mask = (2 * new.len()).next_power_of_two().max(2) - 1;
        let mut table = vec![FREE; mask + 1];
        let (mut keys, mut counts) = (Vec::<Key>::new(), Vec::<u32>::new());
        let mut cell_of = Vec::with_capacity(new.len());
        for e in new {
            let mut i = cell_hash(e.key) as usize & mask;
            let cell = loop {
                match table[i] {
                    FREE => {
                        table[i] = keys.len() as u32;
                        keys.push(e.key);
                        counts.push(0);
                        break table[i];
                    }
                    c if keys[c as usize] == e.key => break c,
                    _ => i = (i + 1) & mask,
                }
            };
            counts[cell as usize] += 1;
            cell_of.push(cell);
        }
        let mut ranked: Vec<u32> = (0..keys.len() as u32).collect();
        // The keys are distinct: one order, whatever the sort.
        ranked.sort_unstable_by_key(|&c| keys[c as usize]);
        Counted {
            keys,
            counts,
            cell_of,
            ranked,
        }
    }
}

/// Writes `e` into lane `l` of `b`, the block's next free lane.
fn set_lane(b: &mut Block, l: usize, e: &Entry) {
    debug_assert_eq!(b.len, l, "lanes are filled in order");
    for c in 0..3 {
        Block::set(&mut b.p[c], l, e.rel[c]);
        Block::set(&mut b.dir[c], l, e.dir[c]);
        Block::set(&mut b.power[c], l, e.power[c]);
    }
    Block::set(&mut b.r2, l, e.r2);
    b.len = l + 1;
}

/// The open-addressed table of `cells` (linear probing, at most half full).
fn table_of(cells: &[Slot]) -> Vec<Slot> {
    let size = (2 * cells.len()).next_power_of_two().max(2);
    let mask = size - 1;
    let mut table = vec![EMPTY; size];
    for &c in cells {
        let mut i = cell_hash(c.key) as usize & mask;
        while table[i].len != 0 {
            i = (i + 1) & mask;
        }
        table[i] = c;
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small xorshift generator, and `n` photons whose keys lie within
    /// `±spread` (each photon's fields name it, so lanes can be checked).
    fn photons(seed: &mut u64, n: usize, spread: i64) -> Vec<Entry> {
        let mut next = || {
            *seed ^= *seed << 13;
            *seed ^= *seed >> 7;
            *seed ^= *seed << 17;
            *seed
        };
        (0..n)
            .map(|i| Entry {
                key: [0; 3].map(|_| (next() % (2 * spread as u64)) as i64 - spread),
                rel: [i as f32, 0.5, 0.25],
                dir: [0.0, -1.0, i as f32],
                power: [i as f32, 1.0, 2.0],
                r2: i as f32,
            })
            .collect()
    }

    /// Counting gives the order of sorting the photons' indices by `(key,
    /// index)`: many photons a cell, cells in no order, keys of both signs
    /// and far apart (hash collisions), no photons, one.
    #[test]
    fn counted_cells_are_the_sorted_order() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        for (n, spread) in [(0, 1), (1, 1), (7, 1), (1000, 3), (5000, 40), (3000, 1 << 40)] {
            let new = photons(&mut seed, n, spread);
            let c = Counted::of(&new);
            let mut rank = vec![0; c.keys.len()];
            for (r, &k) in c.ranked.iter().enumerate() {
                rank[k as usize] = r;
            }
            let mut counted: Vec<u32> = (0..n as u32).collect();
            counted.sort_by_key(|&i| rank[c.cell_of[i as usize] as usize]);
            let mut sorted: Vec<u32> = (0..n as u32).collect();
            sorted.sort_by_key(|&i| (new[i as usize].key, i));
            assert_eq!(counted, sorted, "{n} photons, keys within ±{spread}");
            for (k, key) in c.keys.iter().enumerate() {
                let of_key = new.iter().filter(|e| e.key == *key).count();
                assert_eq!(c.counts[k] as usize, of_key);
            }
        }
    }

    /// After photons are added in several batches, each cell holds the
    /// photons of its key in the order added, lane after lane, every block
    /// full but the last, and unused lanes empty: what pushing them one by
    /// one gives.
    #[test]
    fn each_cell_holds_its_photons_in_the_order_added() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        // Boxes of 8, 64 and 5 832 cells (dense) and of 2^123 (hashed).
        for spread in [1, 2, 9, 1 << 40] {
            let mut grid = Grid::default();
            let mut all: Vec<Entry> = Vec::new();
            for n in [0, 1, 3, 50, 0, 400, 7] {
                let new = photons(&mut seed, n, spread);
                let keys_before: Vec<Key> = grid.keys().collect();
                let opened = grid.add(&new);
                all.extend(&new);
                let mut fresh: Vec<Key> = new.iter().map(|e| e.key).filter(|k| !keys_before.contains(k)).collect();
                fresh.sort();
                fresh.dedup();
                assert_eq!(opened, fresh);
                for key in grid.keys() {
                    let want: Vec<&Entry> = all.iter().filter(|e| e.key == key).collect();
                    let blocks = grid.get(key, cell_hash(key)).expect("an occupied cell");
                    assert_eq!(blocks.len(), want.len().div_ceil(BLOCK));
                    for (j, b) in blocks.iter().enumerate() {
                        let lanes = &want[j * BLOCK..want.len().min((j + 1) * BLOCK)];
                        assert_eq!(b.len, lanes.len());
                        for l in 0..BLOCK {
                            let e = lanes.get(l);
                            assert_eq!(b.p[0][l], e.map_or(f32::INFINITY, |e| e.rel[0]));
                            assert_eq!(b.dir[2][l], e.map_or(0.0, |e| e.dir[2]));
                            assert_eq!(b.power[0][l], e.map_or(0.0, |e| e.power[0]));
                            assert_eq!(b.r2[l], e.map_or(0.0, |e| e.r2));
                        }
                    }
                }
            }
            assert_eq!(matches!(grid.find, Find::Dense(_)), spread < 1 << 40, "spread {spread}");
            assert_eq!(grid.keys().count(), {
                let mut k: Vec<Key> = all.iter().map(|e| e.key).collect();
                k.sort();
                k.dedup();
                k.len()
            });
        }
    }

    /// The dense index finds what the hashed table finds, for every key of
    /// the box and one cell around it (and far outside), with photons in
    /// few cells of a box (so most of its cells are empty).
    #[test]
    fn the_dense_index_finds_what_the_table_finds() {
        let mut seed = 0x1234_5678_9abc_def1_u64;
        let mut grid = Grid::default();
        let mut new = photons(&mut seed, 40, 6);
        new.push(Entry {
            key: [-6, 5, 0],
            ..new[0]
        });
        grid.add(&new);
        let Find::Dense(dense) = &grid.find else {
            panic!("a box of {:?} cells for {} is dense", [12, 12, 12], grid.cells.len())
        };
        let table = table_of(&grid.cells);
        let hashed = Grid {
            blocks: grid.blocks.clone(),
            cells: grid.cells.clone(),
            find: Find::Hashed(table),
        };
        let mut seen = 0;
        for i in dense.lo[0] - 1..=dense.lo[0] + dense.dims[0] as i64 {
            for j in dense.lo[1] - 1..=dense.lo[1] + dense.dims[1] as i64 {
                for k in dense.lo[2] - 1..=dense.lo[2] + dense.dims[2] as i64 {
                    let key = [i, j, k];
                    // Where in its grid's blocks the slice starts, and how long.
                    let at = |g: &Grid| {
                        g.get(key, cell_hash(key))
                            .map(|v| (v.as_ptr() as usize - g.blocks.as_ptr() as usize, v.len()))
                    };
                    let (a, b) = (at(&grid), at(&hashed));
                    assert_eq!(a, b, "{key:?}");
                    seen += usize::from(a.is_some());
                }
            }
        }
        assert_eq!(seen, grid.cells.len());
        for far in [[i64::MIN, 0, 0], [0, i64::MAX, 0], [0, 0, -1 << 40]] {
            assert!(grid.get(far, cell_hash(far)).is_none());
        }
    }
}
