//! The block layout of `K_q`: which DOFs form its diagonal blocks and which cables fill each,
//! derived from the routing's structure ([`Routing::dof_blocks`]).

use std::ops::Range;

use sinew_routing::Routing;

use crate::colmajor::ColMajor;

/// The largest block of `K_q` the structured solve handles (a universal joint is 2).
pub(crate) const MAX_BLOCK: usize = 4;

/// Consecutive blocks of DOFs over which `K_q` is block diagonal: no cable's DOFs straddle two
/// blocks (`J_c` and the Hessians are exactly zero outside each cable's range).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BlockLayout {
    dof: usize,
    /// Block `k` is `starts[k]..starts[k + 1]`.
    starts: Vec<usize>,
    /// The cables of block `k`, in routing order: `cables[cable_starts[k]..cable_starts[k + 1]]`.
    cables: Vec<usize>,
    cable_starts: Vec<usize>,
    cable_count: usize,
    max_block: usize,
}

impl BlockLayout {
    /// The layout of `routing`: its DOF blocks, and each cable in the block of its DOFs (a
    /// cable that crosses no joint in none).
    pub(crate) fn new(routing: &Routing) -> BlockLayout {
        let n = routing.dof();
        let blocks = routing.dof_blocks();
        let mut starts: Vec<usize> = blocks.iter().map(|b| b.start).collect();
        starts.push(n);
        let max_block = blocks.iter().map(|b| b.len()).max().unwrap_or(0);
        let mut cables = Vec::with_capacity(routing.cable_count());
        let mut cable_starts = Vec::with_capacity(blocks.len() + 1);
        for block in blocks {
            cable_starts.push(cables.len());
            cables.extend(
                routing
                    .cables()
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| !c.dofs.is_empty() && block.contains(&c.dofs.start))
                    .map(|(c, _)| c),
            );
        }
        cable_starts.push(cables.len());
        BlockLayout {
            dof: n,
            starts,
            cables,
            cable_starts,
            cable_count: routing.cable_count(),
            max_block,
        }
    }

    /// The number of DOFs.
    pub(crate) fn dof(&self) -> usize {
        self.dof
    }

    /// The number of cables of the routing.
    pub(crate) fn cable_count(&self) -> usize {
        self.cable_count
    }

    /// Whether the structured solve applies (every block at most [`MAX_BLOCK`]).
    pub(crate) fn structured(&self) -> bool {
        self.max_block <= MAX_BLOCK
    }

    pub(crate) fn blocks(
        &self,
    ) -> impl DoubleEndedIterator<Item = Range<usize>> + ExactSizeIterator + '_ {
        self.starts.windows(2).map(|w| w[0]..w[1])
    }

    /// The cables of block `k`, in routing order.
    pub(crate) fn cables_of(&self, k: usize) -> &[usize] {
        match (self.cable_starts.get(k), self.cable_starts.get(k + 1)) {
            (Some(&lo), Some(&hi)) => &self.cables[lo..hi],
            _ => &[],
        }
    }

    /// The number of blocks.
    pub(crate) fn count(&self) -> usize {
        self.starts.len() - 1
    }
}

/// Zero the entries of `m` inside the blocks of `layout`.
pub(crate) fn zero_blocks(layout: &BlockLayout, m: &mut ColMajor) {
    for block in layout.blocks() {
        for c in block.clone() {
            m.col_mut(c)[block.clone()].fill(0.0);
        }
    }
}
