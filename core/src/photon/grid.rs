//! One level's photons for fixed-radius queries: the blocks of every
//! occupied cell side by side in one array, cells in key order (so the
//! cells next to each other along the last axis are next to each other in
//! memory), found through a small open-addressed table of the occupied
//! cells. A query touches one or two table slots and the cell's contiguous
//! blocks, where a hash map of per-cell vectors cost a miss for the bucket,
//! one for the vector's header and one for its blocks (issue 29.3: half of
//! the gather's time in rim-lens was those misses, `perf`).

use super::{BLOCK, Block, Key, cell_hash};

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
    /// A power of two long, at most half full (empty before any photon).
    table: Vec<Slot>,
}

impl Grid {
    /// The blocks of cell `k` of hash `h` ([`cell_hash`]; none when it
    /// holds no photon).
    #[inline(always)]
    pub(super) fn get(&self, k: Key, h: u64) -> Option<&[Block]> {
        let mask = self.table.len().checked_sub(1)?;
        let mut i = h as usize & mask;
        loop {
            let s = self.table[i];
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

    /// Adds photons to the cells of side `cell`. A cell's photons, old and
    /// new, are then laid out in Morton order of their place in the cell
    /// (ties in the order they came: the old ones, then the new ones as
    /// given), so that a block's eight photons lie close together and its
    /// bounds ([`Block::lo`], [`Block::hi`]) let a query pass it by.
    pub(super) fn add(&mut self, new: &[Entry], cell: f32) {
        let codes: Vec<u32> = new.iter().map(|e| morton(e.rel, cell)).collect();
        let mut order: Vec<u32> = (0..new.len() as u32).collect();
        order.sort_unstable_by_key(|&i| (new[i as usize].key, codes[i as usize], i));
        let mut old: Vec<Slot> = self.table.iter().filter(|s| s.len > 0).copied().collect();
        old.sort_unstable_by_key(|s| s.key);
        let mut blocks = Vec::with_capacity(self.blocks.len() + new.len() / 2 + 1);
        let mut cells = Vec::with_capacity(old.len() + new.len() / 4 + 1);
        let mut here: Vec<(u32, Entry)> = Vec::new();
        let (mut a, mut b) = (0, 0);
        while a < old.len() || b < order.len() {
            let from_old = old.get(a).map(|s| s.key);
            let from_new = order.get(b).map(|&i| new[i as usize].key);
            let key = match (from_old, from_new) {
                (Some(x), Some(y)) => x.min(y),
                (x, y) => x.or(y).unwrap_or_default(),
            };
            let start = blocks.len();
            let kept = if from_old == Some(key) {
                a += 1;
                let s = old[a - 1];
                &self.blocks[s.start as usize..(s.start + s.len) as usize]
            } else {
                &[]
            };
            if from_new != Some(key) {
                // No new photon here: the cell's blocks as they were.
                blocks.extend_from_slice(kept);
            } else {
                // The old photons are in Morton order already, the new ones
                // sorted by code then order: merged (old first on ties),
                // they are what a stable sort of them all would give.
                here.clear();
                for bl in kept {
                    here.extend((0..bl.len).map(|l| bl.entry(key, l)).map(|e| (morton(e.rel, cell), e)));
                }
                let split = here.len();
                while let Some(&i) = order.get(b).filter(|&&i| new[i as usize].key == key) {
                    here.push((codes[i as usize], new[i as usize]));
                    b += 1;
                }
                merge_in_place(&mut here, split);
                for chunk in here.chunks(BLOCK) {
                    blocks.push(Block::of(chunk.iter().map(|c| c.1)));
                }
            }
            cells.push(Slot {
                key,
                start: start as u32,
                len: (blocks.len() - start) as u32,
            });
        }
        self.blocks = blocks;
        self.table = table_of(&cells);
    }
}

/// Merges the two runs `v[..split]` and `v[split..]`, each in order of its
/// codes, into one: on equal codes the first run's entry goes first.
fn merge_in_place(v: &mut Vec<(u32, Entry)>, split: usize) {
    if split == 0 || split == v.len() {
        return;
    }
    let (first, second) = v.split_at(split);
    let mut out = Vec::with_capacity(v.len());
    let (mut i, mut j) = (0, 0);
    while i < first.len() || j < second.len() {
        if j == second.len() || (i < first.len() && first[i].0 <= second[j].0) {
            out.push(first[i]);
            i += 1;
        } else {
            out.push(second[j]);
            j += 1;
        }
    }
    *v = out;
}

/// Sixteen steps a side of a cell: the Morton code (12 bits) of the step
/// that holds the point `rel` from the cell's low corner.
fn morton(rel: [f32; 3], cell: f32) -> u32 {
    let step = |v: f32| ((v / cell * 16.0) as u32).min(15);
    let spread = |v: u32| (0..4).fold(0, |m, i| m | ((v >> i) & 1) << (3 * i));
    spread(step(rel[0])) | spread(step(rel[1])) << 1 | spread(step(rel[2])) << 2
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
