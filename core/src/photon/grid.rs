//! One level's photons for fixed-radius queries: the blocks of every
//! occupied cell side by side in one array, cells in key order (so the
//! cells next to each other along the last axis are next to each other in
//! memory), found through a small open-addressed table of the occupied
//! cells. A query touches one or two table slots and the cell's contiguous
//! blocks, where a hash map of per-cell vectors cost a miss for the bucket,
//! one for the vector's header and one for its blocks (issue 29.3: half of
//! the gather's time in rim-lens was those misses, `perf`).

use super::cells::{Key, cell_hash};
use super::{BLOCK, Block};
use rayon::prelude::*;

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
            let s = &self.table[i];
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

    /// The occupied cells' keys.
    pub(super) fn keys(&self) -> impl Iterator<Item = Key> + '_ {
        self.table.iter().filter(|s| s.len > 0).map(|s| s.key)
    }

    /// Adds photons, each after those already in its cell and in the order
    /// given (so a cell's blocks are what inserting them one by one gives).
    /// Returns the keys of the cells that held no photon before, in order.
    pub(super) fn add(&mut self, new: &[Entry]) -> Vec<Key> {
        let mut order: Vec<u32> = (0..new.len() as u32).collect();
        // Keys with their index are unique: the same order on any threads.
        order.par_sort_unstable_by_key(|&i| (new[i as usize].key, i));
        let mut old: Vec<Slot> = self.table.iter().filter(|s| s.len > 0).copied().collect();
        old.sort_unstable_by_key(|s| s.key);
        let mut blocks = Vec::with_capacity(self.blocks.len() + new.len() / 2 + 1);
        let mut cells = Vec::with_capacity(old.len() + new.len() / 4 + 1);
        let mut opened = Vec::new();
        let (mut a, mut b) = (0, 0);
        while a < old.len() || b < order.len() {
            let from_old = old.get(a).map(|s| s.key);
            let from_new = order.get(b).map(|&i| new[i as usize].key);
            let key = match (from_old, from_new) {
                (Some(x), Some(y)) => x.min(y),
                (x, y) => x.or(y).unwrap_or_default(),
            };
            let start = blocks.len();
            if from_old == Some(key) {
                let s = old[a];
                blocks.extend_from_slice(&self.blocks[s.start as usize..(s.start + s.len) as usize]);
                a += 1;
            } else {
                opened.push(key);
            }
            while let Some(e) = order.get(b).map(|&i| &new[i as usize]).filter(|e| e.key == key) {
                push_lane(&mut blocks, start, e);
                b += 1;
            }
            let len = (blocks.len() - start) as u32;
            cells.push(Slot {
                key,
                start: start as u32,
                len,
            });
        }
        self.blocks = blocks;
        self.table = table_of(&cells);
        opened
    }
}

/// Puts `e` in the last block of the cell whose blocks start at `start`,
/// or in a new block when that one is full (or the cell has none yet).
fn push_lane(blocks: &mut Vec<Block>, start: usize, e: &Entry) {
    if blocks.len() == start || blocks.last().is_some_and(|b| b.len == BLOCK) {
        blocks.push(Block::EMPTY);
    }
    // ok: a block was pushed above when the cell had none with room.
    let b = blocks.last_mut().expect("a block with room");
    let l = b.len;
    for c in 0..3 {
        Block::set(&mut b.p[c], l, e.rel[c]);
        Block::set(&mut b.dir[c], l, e.dir[c]);
        Block::set(&mut b.power[c], l, e.power[c]);
    }
    Block::set(&mut b.r2, l, e.r2);
    b.len += 1;
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
