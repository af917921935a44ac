//! The BVH's construction: the binary tree's topology by binned SAH (Wald, "On fast
//! construction of SAH-based bounding volume hierarchies", IEEE RT 2007), kept apart from the
//! 4-wide tree it becomes and the traversal (`bvh.rs`).
//!
//! The build reads one contiguous array of primitive references, each its box with its index
//! in the box's fourth lane, and partitions it in place: every pass over a node's primitives
//! streams memory, and the box operations are four-lane loops the compiler turns into SIMD.
//! One pass bins a node's primitives on all three axes; the partition that follows gathers
//! both children's boxes and centre boxes, so a node never rescans its primitives for them.
//! Large nodes bin in parallel chunks (counts add and boxes unite exactly, in any grouping)
//! and build their two subtrees in parallel into slots fixed by the tree alone, so the tree is
//! the same whatever the thread count. The tree only chooses the topology: `bvh.rs` refits
//! every box exactly from the primitives.

use super::{Aabb, Primitive};
use glam::DVec3;
use rayon::prelude::*;

/// SAH bins per axis, at most: a node of m primitives takes `min(m, NUM_BINS)`.
const NUM_BINS: usize = 16;
/// Nodes of at most this many primitives are leaves.
const MAX_LEAF_SIZE: usize = 4;
/// Nodes of up to this many primitives become leaves when the SAH finds no split cheaper
/// than a leaf.
const MAX_SAH_LEAF_SIZE: usize = 16;
/// Below this depth nodes are split at the SAH's best plane; from it on, at the median of the
/// widest axis of their centres, which halves the count each level. So no leaf is deeper
/// than `SAH_MAX_DEPTH + 32` for up to 2^31 primitives (node indices are `u32`), however
/// unbalanced the SAH's splits are (primitives spaced geometrically make it peel one off per
/// level).
pub(super) const SAH_MAX_DEPTH: usize = 64;
/// Centre extents at most this (m) are not split along.
const MIN_EXTENT_M: f64 = 1e-12;
/// Nodes of at least this many primitives build their two subtrees in parallel.
const PARALLEL_BUILD_MIN: usize = 4096;
/// Nodes of at least this many primitives bin them in parallel chunks of a quarter of it.
const PARALLEL_BINNING_MIN: usize = 32_768;

/// Four f64 lanes: x, y, z and a payload lane the box operations carry along.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(32))]
struct Lanes([f64; 4]);

impl Lanes {
    const INFINITY: Lanes = Lanes([f64::INFINITY; 4]);
    const NEG_INFINITY: Lanes = Lanes([f64::NEG_INFINITY; 4]);

    /// Lane-wise minimum.
    #[inline(always)]
    fn min(self, o: Lanes) -> Lanes {
        let (a, b) = (self.0, o.0);
        Lanes([
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[2].min(b[2]),
            a[3].min(b[3]),
        ])
    }

    /// Lane-wise maximum.
    #[inline(always)]
    fn max(self, o: Lanes) -> Lanes {
        let (a, b) = (self.0, o.0);
        Lanes([
            a[0].max(b[0]),
            a[1].max(b[1]),
            a[2].max(b[2]),
            a[3].max(b[3]),
        ])
    }

    /// `(self + o) · 0.5` lane-wise: a box's centre from its corners.
    #[inline(always)]
    fn midpoint(self, o: Lanes) -> Lanes {
        let (a, b) = (self.0, o.0);
        Lanes([
            (a[0] + b[0]) * 0.5,
            (a[1] + b[1]) * 0.5,
            (a[2] + b[2]) * 0.5,
            (a[3] + b[3]) * 0.5,
        ])
    }
}

/// A box over four lanes (the fourth ignored).
#[derive(Debug, Clone, Copy, PartialEq)]
struct LaneBox {
    lo: Lanes,
    hi: Lanes,
}

impl LaneBox {
    const EMPTY: LaneBox = LaneBox {
        lo: Lanes::INFINITY,
        hi: Lanes::NEG_INFINITY,
    };

    #[inline(always)]
    fn union(self, o: LaneBox) -> LaneBox {
        LaneBox {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    #[inline(always)]
    fn grow(&mut self, p: Lanes) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    /// Surface area over x, y, z (0 for an empty box), m².
    fn surface_area(&self) -> f64 {
        let d: [f64; 3] = std::array::from_fn(|a| (self.hi.0[a] - self.lo.0[a]).max(0.0));
        2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0])
    }
}

/// A primitive during the build: its box, with its index (exact in f64) in `lo`'s fourth
/// lane.
#[derive(Debug, Clone, Copy)]
struct BuildRef {
    lo: Lanes,
    hi: Lanes,
}

impl BuildRef {
    #[inline(always)]
    fn index(&self) -> u32 {
        self.lo.0[3] as u32
    }

    #[inline(always)]
    fn centre(&self) -> Lanes {
        self.lo.midpoint(self.hi)
    }

    #[inline(always)]
    fn bounds(&self) -> LaneBox {
        LaneBox {
            lo: self.lo,
            hi: self.hi,
        }
    }
}

/// A node of the binary tree: its box's surface area (which children the 4-wide tree opens
/// first), and where it leads.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct BinaryNode {
    pub(super) area_m2: f64,
    /// Interior: index of the left child (right = left + 1). Leaf: first primitive.
    pub(super) first: u32,
    /// Number of primitives in a leaf; 0 for an interior node.
    pub(super) count: u32,
}

/// The binary tree's topology: its nodes (the root is node 0; slots no node needs stay
/// default and unlinked), the primitives in the tree's order (a leaf's `first..first +
/// count`), and the depth of its deepest node (the root's is 0).
pub(super) struct BinaryTree {
    pub(super) nodes: Vec<BinaryNode>,
    refs: Vec<BuildRef>,
    pub(super) depth: usize,
}

impl BinaryTree {
    /// Index in the input of the primitive at `position` of the tree's order.
    #[inline]
    pub(super) fn primitive_at(&self, position: usize) -> u32 {
        self.refs[position].index()
    }

    /// Number of primitives.
    pub(super) fn len(&self) -> usize {
        self.refs.len()
    }

    /// The exact box of the primitives at `positions` of the tree's order.
    pub(super) fn bounds_of(&self, positions: std::ops::Range<usize>) -> Aabb {
        let b = self.refs[positions]
            .iter()
            .fold(LaneBox::EMPTY, |b, r| b.union(r.bounds()));
        Aabb {
            min: DVec3::new(b.lo.0[0], b.lo.0[1], b.lo.0[2]),
            max: DVec3::new(b.hi.0[0], b.hi.0[1], b.hi.0[2]),
        }
    }
}

/// A node's box and its primitives' centres' box, handed down from its parent's partition.
#[derive(Clone, Copy)]
struct NodeBoxes {
    bounds: LaneBox,
    centres: LaneBox,
}

impl NodeBoxes {
    const EMPTY: NodeBoxes = NodeBoxes {
        bounds: LaneBox::EMPTY,
        centres: LaneBox::EMPTY,
    };

    #[inline(always)]
    fn add(&mut self, r: &BuildRef) {
        self.bounds = self.bounds.union(r.bounds());
        self.centres.grow(r.centre());
    }

    fn merged(mut self, o: NodeBoxes) -> NodeBoxes {
        self.bounds = self.bounds.union(o.bounds);
        self.centres = self.centres.union(o.centres);
        self
    }

    fn of(refs: &[BuildRef]) -> NodeBoxes {
        refs.iter().fold(NodeBoxes::EMPTY, |mut b, r| {
            b.add(r);
            b
        })
    }
}

/// Builds the binary tree over `primitives` (at least one, fewer than 2^32).
pub(super) fn build_binary(primitives: &[Primitive]) -> BinaryTree {
    let n = primitives.len();
    assert!(n > 0 && n <= u32::MAX as usize, "{n} primitives");
    let mut refs: Vec<BuildRef> = primitives
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let b = p.bounds();
            BuildRef {
                lo: Lanes([b.min.x, b.min.y, b.min.z, i as f64]),
                hi: Lanes([b.max.x, b.max.y, b.max.z, 0.0]),
            }
        })
        .collect();
    let boxes = refs
        .par_chunks(PARALLEL_BINNING_MIN / 4)
        .map(NodeBoxes::of)
        .reduce(|| NodeBoxes::EMPTY, NodeBoxes::merged);
    // Every node of m primitives owns 2m − 1 slots: itself, then its two children, then each
    // child's descendants in turn (2k − 2 slots for a child of k). The layout is a function
    // of the tree alone, so subtrees build in parallel into disjoint slots (slots a leaf does
    // not need stay unused; the 4-wide tree follows the links).
    let mut nodes = vec![BinaryNode::default(); 2 * n - 1];
    let (root, rest) = nodes.split_at_mut(1);
    let depth = build_node(
        &mut root[0],
        rest,
        1,
        &mut refs,
        0,
        0,
        boxes,
        &mut Bins::new(),
    );
    BinaryTree { nodes, refs, depth }
}

/// The bins of one node on all three axes: each bin's primitive count and box.
#[derive(Clone, Copy)]
struct Bins {
    counts: [[u32; NUM_BINS]; 3],
    boxes: [[LaneBox; NUM_BINS]; 3],
}

impl Bins {
    const EMPTY: Bins = Bins {
        counts: [[0; NUM_BINS]; 3],
        boxes: [[LaneBox::EMPTY; NUM_BINS]; 3],
    };

    /// Empty bins (scratch for a build).
    fn new() -> Bins {
        Bins::EMPTY
    }

    fn merged(mut self, o: Bins) -> Bins {
        for axis in 0..3 {
            for k in 0..NUM_BINS {
                self.counts[axis][k] += o.counts[axis][k];
                self.boxes[axis][k] = self.boxes[axis][k].union(o.boxes[axis][k]);
            }
        }
        self
    }
}

/// Where a node's centres fall among its bins: `bin(c)[axis]` is the bin of centre `c`.
#[derive(Clone, Copy)]
struct Binning {
    lo: Lanes,
    scale: Lanes,
    /// Bins per axis.
    bins: usize,
}

impl Binning {
    /// `bins` bins spanning the centres' box; an axis of no extent has every centre in bin 0.
    fn new(centres: &LaneBox, bins: usize) -> (Binning, [bool; 3]) {
        let mut scale = [0.0; 4];
        let mut live = [false; 3];
        for axis in 0..3 {
            let extent = centres.hi.0[axis] - centres.lo.0[axis];
            live[axis] = extent > MIN_EXTENT_M;
            if live[axis] {
                scale[axis] = bins as f64 / extent;
            }
        }
        let binning = Binning {
            lo: centres.lo,
            scale: Lanes(scale),
            bins,
        };
        (binning, live)
    }

    /// The bin of centre `c` along `axis`.
    #[inline(always)]
    fn bin(&self, c: &Lanes, axis: usize) -> usize {
        let x = (c.0[axis] - self.lo.0[axis]) * self.scale.0[axis];
        // Clamped first, the conversion needs no saturation (NaN takes bin 0).
        x.clamp(0.0, (self.bins - 1) as f64) as u32 as usize
    }

    /// Bins `refs` on all three axes into `bins` (its first `self.bins` bins cleared first).
    fn fill(&self, refs: &[BuildRef], bins: &mut Bins) {
        for axis in 0..3 {
            bins.counts[axis][..self.bins].fill(0);
            bins.boxes[axis][..self.bins].fill(LaneBox::EMPTY);
        }
        for r in refs {
            let c = r.centre();
            let b = r.bounds();
            for axis in 0..3 {
                let k = self.bin(&c, axis);
                bins.counts[axis][k] += 1;
                bins.boxes[axis][k] = bins.boxes[axis][k].union(b);
            }
        }
    }
}

/// Builds the subtree of `refs` (positions `first..` of the whole order) into `root` and its
/// descendants' slots `rest` (2m − 2 of them, the first at index `rest_base` of the whole
/// array), given the refs' boxes: binned SAH down to [`SAH_MAX_DEPTH`], then median splits.
/// Returns the depth of its deepest node.
#[allow(clippy::too_many_arguments)]
fn build_node(
    root: &mut BinaryNode,
    rest: &mut [BinaryNode],
    rest_base: usize,
    refs: &mut [BuildRef],
    first: usize,
    depth: usize,
    boxes: NodeBoxes,
    bins: &mut Bins,
) -> usize {
    let count = refs.len();
    *root = BinaryNode {
        area_m2: boxes.bounds.surface_area(),
        first: first as u32,
        count: count as u32,
    };
    if count <= MAX_LEAF_SIZE {
        return depth;
    }
    let split = if depth < SAH_MAX_DEPTH {
        let Some((binning, axis, bin)) = best_split(refs, &boxes, bins) else {
            return depth;
        };
        partition(refs, |c| binning.bin(c, axis) < bin)
    } else {
        None
    };
    let (left, left_boxes, right_boxes) = match split {
        Some(s) => s,
        None => median_split(refs, &boxes.centres),
    };
    root.first = rest_base as u32;
    root.count = 0;
    let (children, descendants) = rest.split_at_mut(2);
    let (left_root, right_root) = children.split_at_mut(1);
    let (left_rest, right_rest) = descendants.split_at_mut(2 * left - 2);
    let (left_refs, right_refs) = refs.split_at_mut(left);
    let (left_base, right_base) = (rest_base + 2, rest_base + 2 + 2 * left - 2);
    let mut build_left = |bins: &mut Bins| {
        build_node(
            &mut left_root[0],
            left_rest,
            left_base,
            left_refs,
            first,
            depth + 1,
            left_boxes,
            bins,
        )
    };
    let mut build_right = |bins: &mut Bins| {
        build_node(
            &mut right_root[0],
            right_rest,
            right_base,
            right_refs,
            first + left,
            depth + 1,
            right_boxes,
            bins,
        )
    };
    let (l, r) = if count >= PARALLEL_BUILD_MIN {
        rayon::join(|| build_left(bins), || build_right(&mut Bins::new()))
    } else {
        (build_left(bins), build_right(bins))
    };
    l.max(r)
}

/// Moves the refs whose centre `goes_left` to the front. Returns how many, with both sides'
/// boxes, or None when one side is empty.
#[inline]
fn partition(
    refs: &mut [BuildRef],
    goes_left: impl Fn(&Lanes) -> bool,
) -> Option<(usize, NodeBoxes, NodeBoxes)> {
    let (mut left, mut right) = (NodeBoxes::EMPTY, NodeBoxes::EMPTY);
    let (mut i, mut j) = (0, refs.len());
    while i < j {
        if goes_left(&refs[i].centre()) {
            left.add(&refs[i]);
            i += 1;
        } else {
            j -= 1;
            refs.swap(i, j);
            right.add(&refs[j]);
        }
    }
    (i > 0 && i < refs.len()).then_some((i, left, right))
}

/// Splits at the median centre along the axis the centres spread widest (ties by index).
fn median_split(refs: &mut [BuildRef], centres: &LaneBox) -> (usize, NodeBoxes, NodeBoxes) {
    let extent: [f64; 3] = std::array::from_fn(|a| centres.hi.0[a] - centres.lo.0[a]);
    let axis = (0..3).fold(0, |best, a| if extent[a] > extent[best] { a } else { best });
    let half = refs.len() / 2;
    refs.select_nth_unstable_by(half, |a, b| {
        a.centre().0[axis]
            .total_cmp(&b.centre().0[axis])
            .then(a.index().cmp(&b.index()))
    });
    let (l, r) = refs.split_at(half);
    (half, NodeBoxes::of(l), NodeBoxes::of(r))
}

/// Binned SAH: the binning, the axis and the bin that starts the right side, for the
/// cheapest split, if one beats a leaf (nodes of more than [`MAX_SAH_LEAF_SIZE`] are always
/// split). `bins` is scratch.
fn best_split(
    refs: &[BuildRef],
    boxes: &NodeBoxes,
    bins: &mut Bins,
) -> Option<(Binning, usize, usize)> {
    let num_bins = refs.len().min(NUM_BINS);
    let (binning, live) = Binning::new(&boxes.centres, num_bins);
    if refs.len() >= PARALLEL_BINNING_MIN {
        *bins = refs
            .par_chunks(PARALLEL_BINNING_MIN / 4)
            .map(|chunk| {
                let mut bins = Bins::EMPTY;
                binning.fill(chunk, &mut bins);
                bins
            })
            .reduce(|| Bins::EMPTY, Bins::merged);
    } else {
        binning.fill(refs, bins);
    }
    let mut best: Option<(f64, usize, usize)> = None;
    for axis in (0..3).filter(|&a| live[a]) {
        let (bin_boxes, bin_counts) = (&bins.boxes[axis][..num_bins], &bins.counts[axis]);
        let mut left_area = [0.0; NUM_BINS];
        let mut left_count = [0u32; NUM_BINS];
        let mut acc = LaneBox::EMPTY;
        let mut n = 0;
        for b in 0..num_bins - 1 {
            acc = acc.union(bin_boxes[b]);
            n += bin_counts[b];
            left_area[b] = acc.surface_area();
            left_count[b] = n;
        }
        let mut acc = LaneBox::EMPTY;
        let mut n = 0;
        for b in (1..num_bins).rev() {
            acc = acc.union(bin_boxes[b]);
            n += bin_counts[b];
            let cost =
                left_area[b - 1] * f64::from(left_count[b - 1]) + acc.surface_area() * f64::from(n);
            if left_count[b - 1] > 0 && n > 0 && best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    let (cost, axis, bin) = best?;
    let leaf_cost = boxes.bounds.surface_area() * refs.len() as f64;
    (cost < leaf_cost || refs.len() > MAX_SAH_LEAF_SIZE).then_some((binning, axis, bin))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane operations against the scalar ones they stand for.
    #[test]
    fn lanes_match_scalar_min_max() {
        let a = Lanes([1.0, -2.0, f64::INFINITY, 4.0]);
        let b = Lanes([0.5, -1.0, 3.0, f64::NEG_INFINITY]);
        assert_eq!(a.min(b), Lanes([0.5, -2.0, 3.0, f64::NEG_INFINITY]));
        assert_eq!(a.max(b), Lanes([1.0, -1.0, f64::INFINITY, 4.0]));
        assert_eq!(a.midpoint(b).0[..2], [0.75, -1.5]);
    }
}
