//! Matching the new facets of one beneath-beyond step along their shared ridges.
//!
//! Every new facet is the cone from the added point over a horizon ridge; two new facets
//! are neighbours when they share a ridge through the added point. A ridge is a set of
//! D-1 vertex indices, keyed by the wrapping sums of two fixed pseudo-random 64-bit
//! words per vertex (Zobrist hashing), so a facet's ridge keys cost one subtraction each
//! from the sums over its vertices. The first sum places the ridge in an open-addressed
//! table of 16-byte slots (cleared slot by slot at the next step); a match needs the
//! first sum and the low 32 bits of the second to agree. Two distinct ridges of a step
//! are therefore confused only if 96 independent bits collide (odds about 2^-96 per
//! pair of ridges, some 10^-23 per step of a few hundred ridges). Comparing the vertex
//! sets instead doubled the cost of a step. The probe and the bookkeeping avoid
//! branches on whether a ridge's partner has been seen, a coin flip that no branch
//! predictor learns.

use std::hint::select_unpredictable;

/// No facet: an offer that found no partner.
pub const NONE: u32 = u32::MAX;

/// The two key words of vertex `v`: SplitMix64 of its index under two seeds (fixed, so
/// runs are repeatable).
#[inline]
pub fn vertex_keys(v: u32) -> [u64; 2] {
    [
        splitmix(v as u64),
        splitmix((v as u64) ^ 0x5851_f42d_4c95_7f2d),
    ]
}

fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(1).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A ridge key: the two wrapping sums of its vertices' key words.
pub type RidgeKey = [u64; 2];

/// One slot of the table (16 bytes, so that a step's table stays in L1): the first key
/// word, the low half of the second, and the waiting facet with its slot.
#[derive(Clone, Copy)]
struct Entry {
    key: u64,
    check: u32,
    /// `facet << 4 | slot`, or [`VACANT`] / [`MATCHED`].
    waiting: u32,
}

const VACANT: u32 = u32::MAX;
const MATCHED: u32 = u32::MAX - 1;
/// Facet ids must stay below this to be packed with a slot (< 16) in 32 bits.
pub const MAX_FACETS: u32 = (MATCHED >> 4) - 1;

const EMPTY: Entry = Entry {
    key: 0,
    check: 0,
    waiting: VACANT,
};

/// Whether `e` holds another ridge than `key`. Whether the slot is vacant or holds the
/// partner is a coin flip, so the two tests are combined by a branch-free select.
#[inline]
fn taken_by_other(e: &Entry, key: u64, check: u32) -> bool {
    let differs = (e.key != key) | (e.check != check);
    select_unpredictable(e.waiting == VACANT, false, differs)
}

/// Open-addressed table of ridges awaiting their second facet.
#[derive(Default)]
pub struct RidgeTable {
    entries: Vec<Entry>,
    /// Slots written in this step, cleared by the next [`Self::begin`].
    used: Vec<u32>,
    /// Offers stored minus offers matched in this step.
    unmatched: usize,
    /// A ridge was offered a third time (not a manifold: degenerate rounding).
    overfull: bool,
}

impl RidgeTable {
    /// Starts a step that will make at most `offers` offers. Each ridge is stored by its
    /// first offer only and the table has at least twice as many slots as offers, so it
    /// stays at most a quarter full.
    pub fn begin(&mut self, offers: usize) {
        for &i in &self.used {
            self.entries[i as usize] = EMPTY;
        }
        self.used.clear();
        let wanted = (2 * offers).next_power_of_two().max(64);
        if self.entries.len() < wanted {
            self.entries = vec![EMPTY; wanted];
        }
        self.unmatched = 0;
        self.overfull = false;
    }

    /// Offers ridge `key` of `facet` (below [`MAX_FACETS`]), where it is the ridge
    /// opposite `slot` (< 16). Returns the facet that offered the same ridge earlier in
    /// this step and its slot, or `(NONE, 0)` after storing this offer. At most as many
    /// offers as announced to [`Self::begin`].
    #[inline]
    pub fn offer(&mut self, key: RidgeKey, facet: u32, slot: u32) -> (u32, u32) {
        let mask = self.entries.len() - 1;
        let check = key[1] as u32;
        let mut i = (key[0] >> 40) as usize & mask;
        // Skip slots holding other ridges (the table is at most a quarter full, so this
        // rarely loops).
        while taken_by_other(&self.entries[i], key[0], check) {
            i = (i + 1) & mask;
        }
        let e = self.entries[i];
        let vacant = e.waiting == VACANT;
        let partner = e.waiting < MATCHED;
        self.overfull |= e.waiting == MATCHED;
        self.unmatched = (self.unmatched + vacant as usize).wrapping_sub(partner as usize);
        self.used.push(i as u32);
        self.entries[i] = Entry {
            key: key[0],
            check,
            waiting: select_unpredictable(vacant, facet << 4 | slot, MATCHED),
        };
        select_unpredictable(partner, (e.waiting >> 4, e.waiting & 15), (NONE, 0))
    }

    /// Whether every offered ridge of this step met exactly one partner.
    pub fn complete(&self) -> bool {
        self.unmatched == 0 && !self.overfull
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_are_matched_once() {
        let mut t = RidgeTable::default();
        t.begin(5);
        assert_eq!(t.offer([7, 1], 1, 2), (NONE, 0));
        assert_eq!(t.offer([9, 1], 1, 3), (NONE, 0));
        // Same first word, other second word: a different ridge.
        assert_eq!(t.offer([7, 2], 3, 1), (NONE, 0));
        assert_eq!(t.offer([7, 1], 4, 0), (1, 2));
        assert!(!t.complete());
        assert_eq!(t.offer([9, 1], 5, 5), (1, 3));
        assert_eq!(t.offer([7, 2], 6, 4), (3, 1));
        assert!(t.complete());
        // A third facet on one ridge.
        assert_eq!(t.offer([7, 1], 8, 0), (NONE, 0));
        assert!(!t.complete());
        // A new step forgets the old entries.
        t.begin(3);
        assert_eq!(t.offer([9, 1], 2, 1), (NONE, 0));
        assert_ne!(vertex_keys(0), vertex_keys(1));
        assert_ne!(vertex_keys(0)[0], vertex_keys(0)[1]);
    }
}
