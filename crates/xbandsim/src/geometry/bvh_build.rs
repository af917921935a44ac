//! The BVH's construction: the binary tree's topology by binned SAH (Wald, "On fast
//! construction of SAH-based bounding volume hierarchies", IEEE RT 2007), kept apart from the
//! 4-wide tree it becomes and the traversal (`bvh.rs`).
//!
//! The build reads one contiguous array of primitive references, each its box in f32 with
//! its index in a spare lane, and partitions it in place: every pass over a node's primitives
//! streams memory, and the box operations are eight-lane loops the compiler turns into SIMD.
//! A box keeps its maxima negated, so the union of two boxes is one lane-wise minimum.
//! One pass bins a node's primitives on all three axes; the partition that follows gathers
//! both children's boxes and centre boxes, so a node never rescans its primitives for them.
//!
//! Large trees are built over clusters (Lauterbach et al., "Fast BVH construction on GPUs",
//! Eurographics 2009; Pantaleoni & Luebke, "HLBVH", HPG 2010): the references are sorted by
//! the Morton codes of their centres and cut into runs of nearby primitives; the SAH swept
//! along that sequence of clusters builds the top of the tree, and each cluster's subtree is
//! built by the binned SAH from its own references, which fit in cache. So only the sort and
//! a few passes touch every reference, rather than every level of the tree.
//!
//! Subtrees build in parallel into slots fixed by the tree alone, and every reduction is a
//! minimum or a count (exact in any grouping), so the tree is the same whatever the thread
//! count. The tree only chooses the topology (f32 boxes suffice for that): `bvh.rs` refits
//! every box exactly from the primitives.

use super::Primitive;
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
const MIN_EXTENT_M: f32 = 1e-12;
/// Nodes of at least this many primitives build their two subtrees in parallel.
const PARALLEL_BUILD_MIN: usize = 4096;
/// Nodes of at least this many primitives bin them in parallel chunks of a quarter of it.
const PARALLEL_BINNING_MIN: usize = 32_768;
/// Trees of at least this many primitives are built over clusters ([`build_top`]).
const CLUSTERED_BUILD_MIN: usize = 65_536;
/// A cluster holds at most this many primitives, unless more share one Morton cell.
const CLUSTER_MAX: usize = 1024;
/// Bits of each axis in a Morton code (3 × 10 = 30 bits).
const MORTON_BITS: u32 = 10;
/// Below this depth the top of a clustered tree cuts its sequence of clusters where the SAH
/// is cheapest; from it on, at the middle cluster. A cluster's subtree goes on from the
/// depth it starts at: SAH splits down to [`SAH_MAX_DEPTH`], then medians. So a leaf is at
/// most `max(TOP_SAH_MAX_DEPTH + 31, SAH_MAX_DEPTH) + 32` deep (at most 2^31 clusters, each
/// of at most 2^31 primitives): `SAH_MAX_DEPTH + 32` for the values here.
const TOP_SAH_MAX_DEPTH: usize = 32;

/// A box over eight f32 lanes: lanes 0–2 the minima along x, y, z, lanes 4–6 the maxima
/// negated; lanes 3 and 7 carry a payload the box operations ignore. The union of two boxes
/// is their lane-wise minimum.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(32))]
struct Box8([f32; 8]);

impl Box8 {
    /// The empty box: minima +∞, maxima −∞.
    const EMPTY: Box8 = Box8([f32::INFINITY; 8]);

    /// Lane-wise minimum: the union of two boxes.
    #[inline(always)]
    fn union(self, o: Box8) -> Box8 {
        let (a, b) = (self.0, o.0);
        Box8(std::array::from_fn(|i| a[i].min(b[i])))
    }

    /// Twice the box's centre as the box of that point.
    #[inline(always)]
    fn centre_point(&self) -> Box8 {
        let a = self.0;
        let c: [f32; 4] = std::array::from_fn(|i| a[i] - a[i + 4]);
        Box8([c[0], c[1], c[2], 0.0, -c[0], -c[1], -c[2], 0.0])
    }

    /// The box's minimum and maximum along `axis`.
    #[inline(always)]
    fn range(&self, axis: usize) -> (f32, f32) {
        (self.0[axis], -self.0[axis + 4])
    }

    /// Surface area over x, y, z (0 for an empty box), m², in f64: finite for any f32 box.
    fn surface_area(&self) -> f64 {
        let d: [f64; 3] = std::array::from_fn(|a| f64::from((-self.0[a + 4] - self.0[a]).max(0.0)));
        2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0])
    }
}

/// A primitive during the build: its box (f32), with its index in lane 3 as the bits of a
/// normal f32 (index + [`INDEX_BITS_OFFSET`]): no lane ever holds a subnormal, which some
/// CPUs handle slowly.
#[derive(Debug, Clone, Copy)]
struct BuildRef(Box8);

/// The build's coordinates are clamped to ±2^125 m: the sum of two stays finite in f32 (the
/// tree only chooses the topology; scenes this large are beyond any radar's reach).
const COORDINATE_LIMIT_M: f64 = 4.253_529_586_511_731e37;

/// The bits of the smallest normal f32.
const INDEX_BITS_OFFSET: u32 = 0x0080_0000;
/// Indices up to here stay below the bits of +∞.
const MAX_PRIMITIVES: usize = (0x7f80_0000 - INDEX_BITS_OFFSET) as usize;

impl BuildRef {
    /// The ref of primitive `index` with box `lo..hi`, each coordinate in f32 within
    /// ±[`COORDINATE_LIMIT_M`].
    fn new(index: usize, lo: glam::DVec3, hi: glam::DVec3) -> BuildRef {
        let index = f32::from_bits(index as u32 + INDEX_BITS_OFFSET);
        let f = |x: f64| x.clamp(-COORDINATE_LIMIT_M, COORDINATE_LIMIT_M) as f32;
        BuildRef(Box8([
            f(lo.x),
            f(lo.y),
            f(lo.z),
            index,
            -f(hi.x),
            -f(hi.y),
            -f(hi.z),
            0.0,
        ]))
    }

    #[inline(always)]
    fn index(&self) -> u32 {
        self.0 .0[3].to_bits() - INDEX_BITS_OFFSET
    }

    /// Twice the centre of the box, as a point's box.
    #[inline(always)]
    fn centre(&self) -> Box8 {
        self.0.centre_point()
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
/// default and unlinked), the primitives' indices in the tree's order (a leaf's `first..first
/// + count`), and the depth of its deepest node (the root's is 0).
pub(super) struct BinaryTree {
    pub(super) nodes: Vec<BinaryNode>,
    pub(super) order: Vec<u32>,
    pub(super) depth: usize,
}

/// A node's box and its primitives' centres' box, handed down from its parent's partition.
#[derive(Clone, Copy)]
struct NodeBoxes {
    bounds: Box8,
    centres: Box8,
}

impl NodeBoxes {
    const EMPTY: NodeBoxes = NodeBoxes {
        bounds: Box8::EMPTY,
        centres: Box8::EMPTY,
    };

    #[inline(always)]
    fn add(&mut self, r: &BuildRef) {
        self.bounds = self.bounds.union(r.0);
        self.centres = self.centres.union(r.centre());
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

/// Builds the binary tree over `primitives` (at least one, at most [`MAX_PRIMITIVES`], about
/// 2.1·10^9).
pub(super) fn build_binary(primitives: &[Primitive]) -> BinaryTree {
    let n = primitives.len();
    assert!(n > 0 && n <= MAX_PRIMITIVES, "{n} primitives");
    let mut refs: Vec<BuildRef> = primitives
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let b = p.bounds();
            BuildRef::new(i, b.min, b.max)
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
    let depth = if n < CLUSTERED_BUILD_MIN {
        build_node(
            &mut root[0],
            rest,
            1,
            &mut refs,
            0,
            0,
            boxes,
            &mut Bins::new(),
        )
    } else {
        let codes = morton_sort(&mut refs, &boxes.centres);
        let mut cuts = Vec::new();
        cut_clusters(&codes, 0, n, &mut cuts);
        drop(codes);
        let clusters: Vec<Cluster> = cuts
            .par_iter()
            .map(|&(start, len)| Cluster {
                boxes: NodeBoxes::of(&refs[start..start + len]),
                len,
            })
            .collect();
        build_top(&mut root[0], rest, 1, &clusters, &mut refs, 0, 0, boxes)
    };
    let order = refs.par_iter().map(BuildRef::index).collect();
    BinaryTree {
        nodes,
        order,
        depth,
    }
}

/// The bins of one node on all three axes: each bin's primitive count and box.
#[derive(Clone, Copy)]
struct Bins {
    counts: [[u32; NUM_BINS]; 3],
    boxes: [[Box8; NUM_BINS]; 3],
}

impl Bins {
    const EMPTY: Bins = Bins {
        counts: [[0; NUM_BINS]; 3],
        boxes: [[Box8::EMPTY; NUM_BINS]; 3],
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
    lo: [f32; 3],
    scale: [f32; 3],
    /// Bins per axis.
    bins: usize,
}

impl Binning {
    /// `bins` bins spanning the centres' box; an axis of no extent has every centre in bin 0.
    fn new(centres: &Box8, bins: usize) -> (Binning, [bool; 3]) {
        let mut binning = Binning {
            lo: [0.0; 3],
            scale: [0.0; 3],
            bins,
        };
        let mut live = [false; 3];
        for axis in 0..3 {
            let (lo, hi) = centres.range(axis);
            let extent = hi - lo;
            binning.lo[axis] = lo;
            live[axis] = extent > MIN_EXTENT_M;
            if live[axis] {
                binning.scale[axis] = bins as f32 / extent;
            }
        }
        (binning, live)
    }

    /// The bin of centre point `c` along `axis`.
    #[inline(always)]
    fn bin(&self, c: &Box8, axis: usize) -> usize {
        let x = (c.0[axis] - self.lo[axis]) * self.scale[axis];
        // Clamped first, the conversion needs no saturation (NaN takes bin 0).
        x.clamp(0.0, (self.bins - 1) as f32) as u32 as usize
    }

    /// Bins `refs` on all three axes into `bins` (its first `self.bins` bins cleared first).
    fn fill(&self, refs: &[BuildRef], bins: &mut Bins) {
        for axis in 0..3 {
            bins.counts[axis][..self.bins].fill(0);
            bins.boxes[axis][..self.bins].fill(Box8::EMPTY);
        }
        for r in refs {
            let c = r.centre();
            for axis in 0..3 {
                let k = self.bin(&c, axis);
                bins.counts[axis][k] += 1;
                bins.boxes[axis][k] = bins.boxes[axis][k].union(r.0);
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
        match best_split(refs, &boxes, bins) {
            Some((binning, axis, bin)) => partition(refs, |c| binning.bin(c, axis) < bin),
            // No split beats a leaf, or no two centres differ enough to split.
            None if count <= MAX_SAH_LEAF_SIZE => return depth,
            None => None,
        }
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
    goes_left: impl Fn(&Box8) -> bool,
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

/// The axis along which the centres in `centres` spread widest (the first of equals).
fn widest_axis(centres: &Box8) -> usize {
    let extent: [f32; 3] = std::array::from_fn(|a| {
        let (lo, hi) = centres.range(a);
        hi - lo
    });
    (0..3).fold(0, |best, a| if extent[a] > extent[best] { a } else { best })
}

/// Splits at the median centre along the axis the centres spread widest (ties by index).
fn median_split(refs: &mut [BuildRef], centres: &Box8) -> (usize, NodeBoxes, NodeBoxes) {
    let axis = widest_axis(centres);
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
        let mut acc = Box8::EMPTY;
        let mut n = 0;
        for b in 0..num_bins - 1 {
            acc = acc.union(bin_boxes[b]);
            n += bin_counts[b];
            left_area[b] = acc.surface_area();
            left_count[b] = n;
        }
        let mut acc = Box8::EMPTY;
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

/// Spreads the low 10 bits of `x` to every third bit.
#[inline(always)]
fn spread_bits(x: u32) -> u32 {
    let mut x = x & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    x = (x | (x << 2)) & 0x0924_9249;
    x
}

/// Sorts `refs` by the Morton codes of their centres on a cubic grid over the centres' box
/// `centres` (its side the largest extent, so a flat scene's cells stay cubes), equal codes in
/// their input order; returns the codes in the new order (a stable radix sort).
fn morton_sort(refs: &mut Vec<BuildRef>, centres: &Box8) -> Vec<u32> {
    let lo: [f32; 3] = std::array::from_fn(|a| centres.range(a).0);
    let side = (0..3)
        .map(|a| centres.range(a).1 - lo[a])
        .fold(0.0f32, f32::max);
    let cells = (1u32 << MORTON_BITS) as f32;
    let scale = if side > MIN_EXTENT_M {
        cells / side
    } else {
        0.0
    };
    let top = ((1u32 << MORTON_BITS) - 1) as f32;
    let mut pairs: Vec<(u64, u32)> = refs
        .par_iter()
        .enumerate()
        .map(|(i, r)| {
            let c = r.centre();
            let cell = |a: usize| ((c.0[a] - lo[a]) * scale).clamp(0.0, top) as u32;
            let code =
                spread_bits(cell(0)) | (spread_bits(cell(1)) << 1) | (spread_bits(cell(2)) << 2);
            (u64::from(code), i as u32)
        })
        .collect();
    crate::special::sort_by_key_stable(&mut pairs);
    *refs = pairs.par_iter().map(|&(_, i)| refs[i as usize]).collect();
    pairs.par_iter().map(|&(code, _)| code as u32).collect()
}

/// Cuts the sorted `codes[start..end]` into clusters `(start, len)`, in order: a range of
/// more than [`CLUSTER_MAX`] codes is split where its highest differing bit turns on.
fn cut_clusters(codes: &[u32], start: usize, end: usize, out: &mut Vec<(usize, usize)>) {
    let (first, last) = (codes[start], codes[end - 1]);
    if end - start <= CLUSTER_MAX || first == last {
        out.push((start, end - start));
        return;
    }
    let bit = 1u32 << (31 - (first ^ last).leading_zeros());
    let mid = start + codes[start..end].partition_point(|&c| c & bit == 0);
    cut_clusters(codes, start, mid, out);
    cut_clusters(codes, mid, end, out);
}

/// A run of the Morton-sorted refs: its boxes and length.
#[derive(Clone, Copy)]
struct Cluster {
    boxes: NodeBoxes,
    len: usize,
}

/// Builds the subtree of the consecutive `clusters`, whose refs are `refs` (positions
/// `first..` of the whole order), like [`build_node`] does for refs: the cut of the sequence
/// with the cheapest SAH down to [`TOP_SAH_MAX_DEPTH`], then the middle cluster; a single
/// cluster is built by [`build_node`]. Returns the depth of its deepest node.
#[allow(clippy::too_many_arguments)]
fn build_top(
    root: &mut BinaryNode,
    rest: &mut [BinaryNode],
    rest_base: usize,
    clusters: &[Cluster],
    refs: &mut [BuildRef],
    first: usize,
    depth: usize,
    boxes: NodeBoxes,
) -> usize {
    if let [_] = clusters {
        return build_node(
            root,
            rest,
            rest_base,
            refs,
            first,
            depth,
            boxes,
            &mut Bins::new(),
        );
    }
    let cut = if depth < TOP_SAH_MAX_DEPTH {
        cheapest_cut(clusters)
    } else {
        clusters.len() / 2
    };
    let (left_clusters, right_clusters) = clusters.split_at(cut);
    let side_boxes = |cs: &[Cluster]| cs.iter().fold(NodeBoxes::EMPTY, |b, c| b.merged(c.boxes));
    let (left_boxes, right_boxes) = (side_boxes(left_clusters), side_boxes(right_clusters));
    let left: usize = left_clusters.iter().map(|c| c.len).sum();
    *root = BinaryNode {
        area_m2: boxes.bounds.surface_area(),
        first: rest_base as u32,
        count: 0,
    };
    let count = refs.len();
    let (children, descendants) = rest.split_at_mut(2);
    let (left_root, right_root) = children.split_at_mut(1);
    let (left_rest, right_rest) = descendants.split_at_mut(2 * left - 2);
    let (left_refs, right_refs) = refs.split_at_mut(left);
    let (left_base, right_base) = (rest_base + 2, rest_base + 2 + 2 * left - 2);
    let mut build_left = || {
        build_top(
            &mut left_root[0],
            left_rest,
            left_base,
            left_clusters,
            left_refs,
            first,
            depth + 1,
            left_boxes,
        )
    };
    let mut build_right = || {
        build_top(
            &mut right_root[0],
            right_rest,
            right_base,
            right_clusters,
            right_refs,
            first + left,
            depth + 1,
            right_boxes,
        )
    };
    let (l, r) = if count >= PARALLEL_BUILD_MIN {
        rayon::join(build_left, build_right)
    } else {
        (build_left(), build_right())
    };
    l.max(r)
}

/// The cut `1..clusters.len()` of a sequence of clusters that minimises the SAH cost: each
/// side's box area times its primitive count (the first of equals).
fn cheapest_cut(clusters: &[Cluster]) -> usize {
    let m = clusters.len();
    let mut right_cost = vec![0.0f64; m];
    let (mut acc, mut n) = (Box8::EMPTY, 0usize);
    for k in (1..m).rev() {
        acc = acc.union(clusters[k].boxes.bounds);
        n += clusters[k].len;
        right_cost[k] = acc.surface_area() * n as f64;
    }
    let (mut acc, mut n) = (Box8::EMPTY, 0usize);
    let mut best = (f64::INFINITY, 1);
    for k in 1..m {
        acc = acc.union(clusters[k - 1].boxes.bounds);
        n += clusters[k - 1].len;
        let cost = acc.surface_area() * n as f64 + right_cost[k];
        if cost < best.0 {
            best = (cost, k);
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The box operations against the scalar ones they stand for.
    #[test]
    fn box_lanes_match_scalar_min_max() {
        let a = Box8([1.0, -2.0, f32::INFINITY, 4.0, -3.0, 1.0, -5.0, 0.0]);
        let b = Box8([0.5, -1.0, 3.0, 9.0, -2.0, 0.5, -6.0, 0.0]);
        let u = a.union(b);
        assert_eq!(u.0[..3], [0.5, -2.0, 3.0]);
        // Maxima of the union: 3, −0.5, 6.
        assert_eq!((u.range(0).1, u.range(1).1, u.range(2).1), (3.0, -0.5, 6.0));
        let c = b.centre_point();
        assert_eq!(c.range(0), (2.5, 2.5));
        assert_eq!(Box8::EMPTY.union(a), a);
        assert_eq!(Box8::EMPTY.surface_area(), 0.0);
    }

    /// Morton codes interleave x, y, z from the lowest bit up.
    #[test]
    fn spread_bits_interleave() {
        assert_eq!(spread_bits(0b1), 0b1);
        assert_eq!(spread_bits(0b11), 0b1001);
        assert_eq!(spread_bits(0x3ff), 0x0924_9249);
    }

    /// Clusters cover the sorted codes in order, each within its size or of one code.
    #[test]
    fn clusters_cover_the_sequence() {
        let mut codes: Vec<u32> = (0..5000u32).map(|i| (i * 7919) % 4096).collect();
        codes.extend(std::iter::repeat_n(9000, 3000));
        codes.sort_unstable();
        let mut cuts = Vec::new();
        cut_clusters(&codes, 0, codes.len(), &mut cuts);
        let mut next = 0;
        for &(start, len) in &cuts {
            assert_eq!(start, next);
            let run = &codes[start..start + len];
            assert!(len <= CLUSTER_MAX || run[0] == run[len - 1]);
            next = start + len;
        }
        assert_eq!(next, codes.len());
    }
}
