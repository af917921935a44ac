//! Bounding-volume hierarchy: binned SAH construction, collapsed to a 4-wide tree whose
//! children's boxes are tested four at a time in f32.
//!
//! Why our own BVH rather than a crate: our primitives are exact analytic shapes (spheres,
//! cylinders, disks, parallelograms) mixed with triangles, and SBR needs f64 hit distances
//! for the carrier phase. A small, allocation-free traversal over an enum of primitives does
//! that directly; `benches/raycast.rs` measures it against brute force (docs/performance.md).
//!
//! The tree is built binary (binned SAH, Wald 2007; `bvh_build.rs`), then each node takes up
//! to four of its descendants as children, the largest first (Dammertz et al., "Shallow
//! bounding volume hierarchies for fast SIMD ray tracing of incoherent rays", EGSR 2008). A
//! node keeps its children's boxes in f32, rounded outward, as four lanes per plane, so one
//! pass of plain lane loops (which the compiler turns into SSE2) tests all four. The f32 test
//! only culls: a box is skipped only when no point of it can lie on the ray before the best
//! hit so far, with the ray's origin rounded toward the box per slab and the products'
//! rounding covered by a relative margin (Ize, "Robust BVH ray traversal", JCGT 2(2), 2013),
//! so every primitive the exact f64 test would meet is still intersected in f64
//! (docs/architecture.md "The ray caster"). Trees or rays beyond f32's reach (coordinates past
//! 10^36 m) take the same traversal with f64 boxes. Coherent rays are searched together as
//! packets (`packet.rs`, [`Bvh::closest_hits`]), with the same hits.

use super::bvh_build::{build_binary, BinaryNode, BinaryTree, SAH_MAX_DEPTH};
use super::{Aabb, Hit, Primitive, Ray};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::Arc;

mod packet;
pub use packet::PACKET_RAYS;

/// The deepest a binary tree gets, and so the 4-wide one (each of its levels is one or two
/// binary levels).
const MAX_DEPTH: usize = SAH_MAX_DEPTH + 32;
/// A traversal pushes up to four children of the node it visits and pops one: at most three
/// pending per level of the 4-wide tree, plus the root's four. This bounds the stack of every
/// tree `build` makes.
const TRAVERSAL_STACK: usize = 3 * MAX_DEPTH + 4;
/// The stack of a traversal of a 4-wide tree no deeper than `SHALLOW_DEPTH` (every tree of a
/// dataset scene): a stack of this size is cleared on each query, not `TRAVERSAL_STACK`'s.
const SHALLOW_STACK: usize = 32;
const SHALLOW_DEPTH: usize = (SHALLOW_STACK - 4) / 3;
/// Coordinates (and ray origins) beyond this take the f64 boxes: f32 reaches 3.4·10^38, so
/// the difference of two coordinates within it stays finite.
const F32_REACH_M: f64 = 1e36;
/// Direction components smaller than this but not zero take the f64 boxes too: their f32
/// reciprocal would lose its relative accuracy (subnormals).
const F32_MIN_DIRECTION: f64 = 1e-20;
/// 2^-23: `|f|` times this is at least one unit in the last place of the f32 `f`.
const F32_EPSILON_HALF_UP: f32 = 1.0 / 8_388_608.0;
/// The relative margins on a box's f32 entry and exit distances: each is a difference, a
/// reciprocal of a rounded direction and a product, at most 4 units of 2^-24 off in all;
/// 2^-20 is 16 of them. The entry distance is shrunk by this factor...
const ENTRY_SHRINK: f32 = 1.0 - 1.0 / 1_048_576.0;
/// ...and the exit distance grown by this one.
const EXIT_GROW: f32 = 1.0 + 1.0 / 1_048_576.0;

/// A node of the 4-wide tree: its children's boxes and where each child leads.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
struct WideNode {
    /// The children's boxes in f32, rounded outward, one lane per child: `planes[2a]` holds
    /// the minima along axis a, `planes[2a + 1]` the maxima. An unused lane holds an empty
    /// box (minima +∞, maxima −∞), which no ray meets.
    planes: [[f32; 4]; 6],
    /// Interior child: its node's index (never 0, the root's). Leaf child: its first
    /// primitive. Unused lane: 0, with `count` 0.
    first: [u32; 4],
    /// Primitives of a leaf child; 0 for an interior child or an unused lane.
    count: [u32; 4],
}

impl WideNode {
    const EMPTY: WideNode = WideNode {
        planes: [
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
        ],
        first: [0; 4],
        count: [0; 4],
    };
}

/// The largest f32 not above `x` (−∞ below f32's range).
fn f32_down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) <= x {
        f
    } else if f == 0.0 {
        -f32::from_bits(1)
    } else if f > 0.0 {
        f32::from_bits(f.to_bits() - 1)
    } else {
        f32::from_bits(f.to_bits() + 1)
    }
}

/// The smallest f32 not below `x` (+∞ above f32's range).
fn f32_up(x: f64) -> f32 {
    -f32_down(-x)
}

/// The reach of the search for a hit on primitive `index` given the `best` hit so far at
/// `t_best_m`: the closest hit is the least (distance, primitive index) pair, so a primitive
/// of a lower index than the best's may also hit at the same distance (just past it: f64's
/// next value up), any other only nearer. The order in which a traversal meets the
/// primitives then never matters, which keeps packet and single-ray searches alike
/// (`packet.rs`).
#[inline(always)]
fn tie_reach(best: &Option<Hit>, index: u32, t_best_m: f64) -> f64 {
    match best {
        Some(b) if index < b.primitive => t_best_m.next_up(),
        _ => t_best_m,
    }
}

/// Searches the leaf `primitives[leaf]` for a hit of `ray` that beats its `best` so far (at
/// `t_best`; [`tie_reach`]), and keeps it there.
#[inline(always)]
fn search_leaf(
    primitives: &[Primitive],
    leaf: std::ops::Range<usize>,
    ray: &Ray,
    best: &mut Option<Hit>,
    t_best: &mut TMax,
) {
    let first = leaf.start;
    for (k, p) in primitives[leaf].iter().enumerate() {
        let index = (first + k) as u32;
        if let Some((t, normal)) = p.intersect(ray, tie_reach(best, index, t_best.m)) {
            *t_best = TMax::new(t);
            *best = Some(Hit {
                t_m: t,
                normal,
                primitive: index,
                object: p.object,
            });
        }
    }
}

/// A pending node of a closest-hit search, and a lower bound on the distance at which the
/// ray enters its box, m.
#[derive(Debug, Clone, Copy, Default)]
struct Pending {
    entry_m: f32,
    node: u32,
}

/// The box test of a traversal: which children of a node the ray may meet before `t_max_m`,
/// as a lane mask, with a lower bound on each one's entry distance.
trait ChildBoxes {
    fn children(&self, node: usize, t_max: TMax) -> ([f32; 4], u32);
}

/// A traversal's search distance, m: in f64, and in f32 rounded up.
#[derive(Debug, Clone, Copy)]
struct TMax {
    m: f64,
    f32_up: f32,
}

impl TMax {
    #[inline]
    fn new(m: f64) -> TMax {
        TMax {
            m,
            f32_up: f32_up(m),
        }
    }
}

/// A ray prepared for the f32 box test. Along each axis the slab's near plane (the minimum
/// for a positive direction, the maximum for a negative one) is measured from the origin
/// rounded toward it, the far plane from the origin rounded away from it, so both distances
/// bound the exact ones before the products round.
struct WideRay<'a> {
    nodes: &'a [WideNode],
    near_plane: [usize; 3],
    far_plane: [usize; 3],
    near_origin: [f32; 3],
    far_origin: [f32; 3],
    inv_dir: [f32; 3],
}

impl<'a> WideRay<'a> {
    /// None when the ray is beyond the f32 test's reach (far origin, subnormal direction).
    #[inline]
    fn new(nodes: &'a [WideNode], ray: &Ray) -> Option<Self> {
        let mut wide = WideRay {
            nodes,
            near_plane: [0; 3],
            far_plane: [0; 3],
            near_origin: [0.0; 3],
            far_origin: [0.0; 3],
            inv_dir: [0.0; 3],
        };
        let mut reach = true;
        for axis in 0..3 {
            let (o, d) = (ray.origin_m[axis], ray.dir[axis]);
            let d_abs = d.abs();
            // (NaN fails both.)
            reach &= o.abs() < F32_REACH_M && (d_abs == 0.0 || d_abs >= F32_MIN_DIRECTION);
            // ±∞ for a zero component: its slab is then (−∞, ∞) or empty, except a ray in a
            // plane of the box, whose 0·∞ = NaN the lane selects ignore (the box is kept).
            let inv = 1.0 / (d as f32);
            let negative = usize::from(inv < 0.0);
            // The origin rounded to nearest is within half a unit of its last place: one
            // unit (|f|·2^-23 or more, and never zero) on either side brackets it. The near
            // plane is measured from the bracket's end toward it (the larger end for a
            // positive direction), the far plane from the other end.
            let f = o as f32;
            let margin = (f.abs() * F32_EPSILON_HALF_UP + f32::MIN_POSITIVE).copysign(inv);
            wide.inv_dir[axis] = inv;
            wide.near_plane[axis] = 2 * axis + negative;
            wide.far_plane[axis] = 2 * axis + 1 - negative;
            wide.near_origin[axis] = f + margin;
            wide.far_origin[axis] = f - margin;
        }
        if !reach {
            return None;
        }
        Some(wide)
    }
}

impl ChildBoxes for WideRay<'_> {
    #[inline(always)]
    fn children(&self, node: usize, t_max: TMax) -> ([f32; 4], u32) {
        let node = &self.nodes[node];
        let mut entry = [0f32; 4];
        let mut exit = [f32::INFINITY; 4];
        for axis in 0..3 {
            let near = &node.planes[self.near_plane[axis]];
            let far = &node.planes[self.far_plane[axis]];
            let (o_near, o_far, inv) = (
                self.near_origin[axis],
                self.far_origin[axis],
                self.inv_dir[axis],
            );
            for c in 0..4 {
                let t_near = (near[c] - o_near) * inv;
                let t_far = (far[c] - o_far) * inv;
                // Compare-and-select: a NaN distance leaves the bound as it was.
                entry[c] = if t_near > entry[c] { t_near } else { entry[c] };
                exit[c] = if t_far < exit[c] { t_far } else { exit[c] };
            }
        }
        let mask = lanes_met(&mut entry, &exit, &[t_max.f32_up; 4]);
        (entry, mask)
    }
}

/// The lanes (a bit each) whose box is met: the slab test's `entry` and `exit` distances
/// widened by their relative margins, the exit capped at the lane's `t_max_up` (f32, rounded
/// up). `entry` is left holding the widened entries.
#[inline(always)]
fn lanes_met<const N: usize>(entry: &mut [f32; N], exit: &[f32; N], t_max_up: &[f32; N]) -> u32 {
    let mut met = [false; N];
    for c in 0..N {
        let lo = entry[c] * ENTRY_SHRINK;
        let hi = exit[c] * EXIT_GROW;
        let hi = if hi < t_max_up[c] { hi } else { t_max_up[c] };
        met[c] = lo <= hi;
        entry[c] = lo;
    }
    met.iter()
        .enumerate()
        .fold(0, |m, (c, &met)| m | (u32::from(met) << c))
}

/// The f64 box test, for trees and rays beyond the f32 one's reach.
struct ExactBoxes<'a> {
    boxes: &'a [[Aabb; 4]],
    origin_m: DVec3,
    inv_dir: DVec3,
}

impl ChildBoxes for ExactBoxes<'_> {
    #[inline]
    fn children(&self, node: usize, t_max: TMax) -> ([f32; 4], u32) {
        let mut entry = [0f32; 4];
        let mut mask = 0;
        // An unused lane's empty box is never met: its near plane is at +∞ along every
        // direction (`Aabb::hit_distance` picks planes by the direction's sign).
        for (c, b) in self.boxes[node].iter().enumerate() {
            if let Some(t) = b.hit_distance(self.origin_m, self.inv_dir, t_max.m) {
                entry[c] = f32_down(t);
                mask |= 1 << c;
            }
        }
        (entry, mask)
    }
}

/// Calls the traversal `$with` of `$bvh` with the stack its depth needs and the box test the
/// tree and the ray allow (f32 where both are within its reach); `$empty` for an empty tree.
macro_rules! traverse {
    ($bvh:ident, $with:ident, $ray:expr, $t_max_m:expr, $empty:expr) => {{
        if $bvh.nodes.is_empty() {
            return $empty;
        }
        let shallow = $bvh.wide_depth <= SHALLOW_DEPTH;
        match ($bvh.wide_ray($ray), shallow) {
            (Some(b), true) => $bvh.$with::<SHALLOW_STACK, _>($ray, $t_max_m, &b),
            (Some(b), false) => $bvh.$with::<TRAVERSAL_STACK, _>($ray, $t_max_m, &b),
            // A ray with a NaN (a zero direction normalised) meets nothing; the f64 boxes
            // would take its NaN distances for a meeting, even with an unused lane.
            (None, _) if $ray.origin_m.is_nan() || $ray.dir.is_nan() => $empty,
            (None, true) => $bvh.$with::<SHALLOW_STACK, _>($ray, $t_max_m, &$bvh.exact_boxes($ray)),
            (None, false) => {
                $bvh.$with::<TRAVERSAL_STACK, _>($ray, $t_max_m, &$bvh.exact_boxes($ray))
            }
        }
    }};
}

/// A hierarchy built once over a shared mesh's primitives in its own frame: the 4-wide tree's
/// links (its boxes are set per copy) and the order of the primitives. Every object that
/// carries the mesh places a copy of it ([`Bvh::build_with_copies`]).
#[derive(Debug)]
pub struct BvhTemplate {
    nodes: Vec<WideNode>,
    /// `order[k]`: the primitive, in the order they were given, at position k of the tree.
    order: Vec<u32>,
    binary_depth: usize,
    wide_depth: usize,
}

impl BvhTemplate {
    /// The template of `primitives` (none if there are none).
    pub fn build(primitives: &[Primitive]) -> Option<BvhTemplate> {
        if primitives.is_empty() {
            return None;
        }
        let tree = build_binary(primitives);
        let (nodes, wide_depth) = collapse(&tree.nodes, primitives.len());
        Some(BvhTemplate {
            nodes,
            order: tree.order,
            binary_depth: tree.depth,
            wide_depth,
        })
    }
}

/// One copy of a template: which, and the box of the copy's primitives as placed (the top
/// level is built over these boxes; the tree's own boxes come from the primitives).
#[derive(Debug, Clone)]
pub struct PlacedCopy {
    /// The shared hierarchy.
    pub template: Arc<BvhTemplate>,
    /// Bounds of the copy's primitives.
    pub bounds: Aabb,
}

/// The size and depths of one subtree that [`Bvh::build_with_copies`] joins under its top.
struct SubtreeSize {
    nodes: usize,
    primitives: usize,
    binary_depth: usize,
    wide_depth: usize,
}

/// Below this depth the top level over subtrees is split by the SAH; from it on, at the
/// middle along the widest axis of the centres (a bound on the top's depth).
const TOP_SAH_DEPTH: usize = 32;

/// A binary tree with one leaf per box (leaf `first` = the box's index, `count` 1), split by
/// the SAH over the boxes' centres (each axis sorted, every cut tried). Returns its nodes and
/// each box's leaf depth. Meant for a scene's objects, not its primitives: a few thousand.
fn build_over_boxes(boxes: &[Aabb]) -> (Vec<BinaryNode>, Vec<usize>) {
    let m = boxes.len();
    let mut nodes = vec![BinaryNode::default(); 2 * m - 1];
    let mut depths = vec![0usize; m];
    let mut items: Vec<u32> = (0..m as u32).collect();
    let mut next = 1;
    let mut stack = vec![(0usize, 0usize, m, 0usize)];
    let mut right_area = vec![0.0f64; m];
    while let Some((at, start, end, depth)) = stack.pop() {
        let span = &mut items[start..end];
        let bounds = span
            .iter()
            .fold(Aabb::EMPTY, |a, &i| a.union(&boxes[i as usize]));
        nodes[at].area_m2 = bounds.surface_area();
        if let [only] = span {
            nodes[at].first = *only;
            nodes[at].count = 1;
            depths[*only as usize] = depth;
            continue;
        }
        let n = span.len();
        let centre = |i: u32, axis: usize| boxes[i as usize].centre()[axis];
        let by_axis = |span: &mut [u32], axis: usize| {
            span.sort_by(|&a, &b| centre(a, axis).total_cmp(&centre(b, axis)).then(a.cmp(&b)))
        };
        let (mut best_axis, mut best_cut) = (0usize, n / 2);
        if depth < TOP_SAH_DEPTH {
            let mut best_cost = f64::INFINITY;
            for axis in 0..3 {
                by_axis(span, axis);
                let mut acc = Aabb::EMPTY;
                for k in (1..n).rev() {
                    acc = acc.union(&boxes[span[k] as usize]);
                    right_area[k] = acc.surface_area() * (n - k) as f64;
                }
                let mut acc = Aabb::EMPTY;
                for k in 1..n {
                    acc = acc.union(&boxes[span[k - 1] as usize]);
                    let cost = acc.surface_area() * k as f64 + right_area[k];
                    if cost < best_cost {
                        (best_cost, best_axis, best_cut) = (cost, axis, k);
                    }
                }
            }
        } else {
            let c = span.iter().fold(Aabb::EMPTY, |a, &i| {
                let p = boxes[i as usize].centre();
                a.union(&Aabb { min: p, max: p })
            });
            let extent = c.max - c.min;
            best_axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
        }
        by_axis(span, best_axis);
        nodes[at].first = next as u32;
        nodes[at].count = 0;
        stack.push((next, start, start + best_cut, depth + 1));
        stack.push((next + 1, start + best_cut, end, depth + 1));
        next += 2;
    }
    (nodes, depths)
}

/// A BVH owning its (reordered) primitives.
#[derive(Debug, Clone)]
pub struct Bvh {
    /// The 4-wide tree; the root is node 0 (none for an empty tree).
    nodes: Vec<WideNode>,
    /// The same children's boxes in f64, for the f64 test only.
    exact_boxes: Vec<[Aabb; 4]>,
    primitives: Vec<Primitive>,
    /// Indices into `primitives`, sorted by object tag and, within one object, ascending:
    /// an object's primitives without a scan of everyone's.
    by_object: Vec<u32>,
    /// Depth of the deepest node of the binary build (the root's is 0).
    binary_depth: usize,
    /// Depth of the deepest node of the 4-wide tree: a traversal's stack holds at most
    /// `3 * wide_depth + 4` entries.
    wide_depth: usize,
    bounds: Aabb,
    /// Whether every box is within the f32 test's reach.
    f32_boxes: bool,
    /// The static level of a two-level hierarchy ([`Bvh::over_static`]): what does not move
    /// (structures, still objects), built once and shared by every revolution's BVH.
    static_level: Option<Arc<Bvh>>,
}

impl Bvh {
    /// Builds the hierarchy over `primitives` (order is not kept).
    pub fn build(primitives: Vec<Primitive>) -> Self {
        if primitives.is_empty() {
            return Bvh {
                nodes: Vec::new(),
                exact_boxes: Vec::new(),
                primitives,
                by_object: Vec::new(),
                binary_depth: 0,
                wide_depth: 0,
                bounds: Aabb::EMPTY,
                f32_boxes: true,
                static_level: None,
            };
        }
        let tree = build_binary(&primitives);
        Bvh::from_tree(primitives, tree)
    }

    /// The hierarchy of a binary tree over `primitives` (not empty): the primitives in the
    /// tree's order, its 4-wide tree and exact boxes.
    fn from_tree(primitives: Vec<Primitive>, tree: BinaryTree) -> Self {
        let reordered: Vec<Primitive> = tree
            .order
            .par_iter()
            .map(|&i| primitives[i as usize])
            .collect();
        drop(primitives);
        let by_object = grouped_by_object(&reordered);
        let (mut wide, wide_depth) = collapse(&tree.nodes, reordered.len());
        drop(tree.nodes);
        let exact_boxes = refit(&mut wide, &reordered);
        Bvh::assembled(
            wide,
            exact_boxes,
            reordered,
            by_object,
            tree.depth,
            wide_depth,
        )
    }

    /// The hierarchy of a finished tree: its nodes with their planes set, their exact boxes
    /// and the primitives in the tree's order.
    fn assembled(
        nodes: Vec<WideNode>,
        exact_boxes: Vec<[Aabb; 4]>,
        primitives: Vec<Primitive>,
        by_object: Vec<u32>,
        binary_depth: usize,
        wide_depth: usize,
    ) -> Bvh {
        let f32_boxes = exact_boxes.par_iter().flatten().all(|b| {
            b.min.cmpge(DVec3::splat(-F32_REACH_M)).all()
                && b.max.cmple(DVec3::splat(F32_REACH_M)).all()
                || b == &Aabb::EMPTY
        });
        let bounds = exact_boxes[0].iter().fold(Aabb::EMPTY, |a, b| a.union(b));
        Bvh {
            nodes,
            exact_boxes,
            primitives,
            by_object,
            binary_depth,
            wide_depth,
            bounds,
            f32_boxes,
            static_level: None,
        }
    }

    /// The hierarchy over `loose` primitives and `copies` of shared templates, with the same
    /// hits as [`Bvh::build`] over all of their primitives; `placed(c, i)` is copy c's
    /// primitive i, the template's primitive i placed. Each copy's subtree is its template's,
    /// its primitives written once, in the tree's order, and its boxes refit (no build per
    /// copy); the loose primitives get a subtree of their own; a top level, built by the SAH
    /// over the subtrees' boxes, joins them (an instanced scene without the per-ray transform
    /// of instancing: every primitive stays in the world's frame).
    pub fn build_with_copies(
        loose: Vec<Primitive>,
        copies: &[PlacedCopy],
        placed: impl Fn(usize, usize) -> Primitive + Sync,
    ) -> Bvh {
        if copies.is_empty() {
            return Bvh::build(loose);
        }
        let loose = (!loose.is_empty()).then(|| Bvh::build(loose));
        // One subtree per copy, then the loose primitives' (if any): their boxes, sizes and
        // depths.
        let mut boxes: Vec<Aabb> = copies.iter().map(|c| c.bounds).collect();
        let mut sizes: Vec<SubtreeSize> = copies
            .iter()
            .map(|c| {
                let t = &c.template;
                SubtreeSize {
                    nodes: t.nodes.len(),
                    primitives: t.order.len(),
                    binary_depth: t.binary_depth,
                    wide_depth: t.wide_depth,
                }
            })
            .collect();
        if let Some(b) = &loose {
            boxes.push(b.bounds);
            sizes.push(SubtreeSize {
                nodes: b.nodes.len(),
                primitives: b.primitives.len(),
                binary_depth: b.binary_depth,
                wide_depth: b.wide_depth,
            });
        }
        let (top_binary, leaf_depths) = build_over_boxes(&boxes);
        let (mut top, _) = collapse(&top_binary, boxes.len());
        // Where each subtree's nodes and primitives start in the joined arrays.
        let (mut node_base, mut primitive_base) = (Vec::new(), Vec::new());
        let (mut num_nodes, mut num_primitives) = (top.len(), 0);
        for size in &sizes {
            node_base.push(num_nodes);
            primitive_base.push(num_primitives);
            num_nodes += size.nodes;
            num_primitives += size.primitives;
        }
        // The top's leaf lanes (one subtree each) become links to the subtrees' roots.
        let mut wide_depth = 0;
        let mut node_depth = vec![0usize; top.len()];
        for w in 0..top.len() {
            for lane in 0..4 {
                let (first, count) = (top[w].first[lane] as usize, top[w].count[lane]);
                if count > 0 {
                    top[w].first[lane] = node_base[first] as u32;
                    top[w].count[lane] = 0;
                    wide_depth = wide_depth.max(node_depth[w] + 1 + sizes[first].wide_depth);
                } else if first != 0 {
                    node_depth[first] = node_depth[w] + 1;
                    wide_depth = wide_depth.max(node_depth[first]);
                }
            }
        }
        let binary_depth = sizes
            .iter()
            .zip(&leaf_depths)
            .map(|(s, d)| s.binary_depth + d)
            .max()
            .unwrap_or(0);
        let subtree_of = |bases: &[usize], at: usize| bases.partition_point(|&b| b <= at) - 1;
        let (loose_nodes, loose_primitives): (&[WideNode], &[Primitive]) = loose
            .as_ref()
            .map_or((&[], &[]), |b| (&b.nodes, &b.primitives));
        // The joined primitives: each copy's in its template's order, then the loose ones.
        let primitives: Vec<Primitive> = (0..num_primitives)
            .into_par_iter()
            .with_min_len(4096)
            .map(|k| {
                let s = subtree_of(&primitive_base, k);
                let at = k - primitive_base[s];
                match copies.get(s) {
                    Some(c) => placed(s, c.template.order[at] as usize),
                    None => loose_primitives[at],
                }
            })
            .collect();
        if wide_depth > MAX_DEPTH {
            // A top level too deep for the traversal's stack: one build over everything.
            return Bvh::build(primitives);
        }
        // The joined nodes: the top's, then each subtree's with its links shifted.
        let top_len = top.len();
        let mut nodes = top;
        nodes.par_extend(
            (top_len..num_nodes)
                .into_par_iter()
                .with_min_len(1024)
                .map(|w| {
                    let s = subtree_of(&node_base, w);
                    let at = w - node_base[s];
                    let mut n = match copies.get(s) {
                        Some(c) => c.template.nodes[at],
                        None => loose_nodes[at],
                    };
                    let (nb, pb) = (node_base[s] as u32, primitive_base[s] as u32);
                    for lane in 0..4 {
                        if n.count[lane] > 0 {
                            n.first[lane] += pb;
                        } else if n.first[lane] != 0 {
                            n.first[lane] += nb;
                        }
                    }
                    n
                }),
        );
        let exact = refit(&mut nodes, &primitives);
        let by_object = grouped_by_object(&primitives);
        Bvh::assembled(
            nodes,
            exact,
            primitives,
            by_object,
            binary_depth,
            wide_depth,
        )
    }

    /// A two-level hierarchy: `dynamic` built now over the shared `static_level`. Queries
    /// take the nearer hit of both; `primitives` and `num_nodes` are the dynamic level's,
    /// an object's primitives and bounds are found in either.
    pub fn over_static(static_level: Arc<Bvh>, dynamic: Vec<Primitive>) -> Bvh {
        let mut bvh = Bvh::build(dynamic);
        bvh.bounds = bvh.bounds.union(&static_level.bounds);
        bvh.static_level = Some(static_level);
        bvh
    }

    /// The static level of a two-level hierarchy, if it is one.
    pub fn static_level(&self) -> Option<&Arc<Bvh>> {
        self.static_level.as_ref()
    }

    /// The primitives, in the hierarchy's order (hit indices refer to this order).
    pub fn primitives(&self) -> &[Primitive] {
        &self.primitives
    }

    /// The primitive a hit of [`Bvh::closest_hit`] met, in whichever level holds it.
    pub fn hit_primitive(&self, hit: &Hit) -> Option<&Primitive> {
        let own = self
            .primitives
            .get(hit.primitive as usize)
            .filter(|p| p.object == hit.object);
        own.or_else(|| {
            self.static_level.as_ref().and_then(|s| {
                s.primitives
                    .get(hit.primitive as usize)
                    .filter(|p| p.object == hit.object)
            })
        })
    }

    /// Number of nodes of the 4-wide tree.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Levels below the root of the deepest leaf of the binary build (0 for a single leaf or
    /// an empty tree).
    pub fn depth(&self) -> usize {
        self.binary_depth
    }

    /// Levels below the root of the deepest node of the 4-wide tree that traversals walk.
    pub fn wide_depth(&self) -> usize {
        self.wide_depth
    }

    /// Whether rays are tested against the f32 boxes: false when some box lies beyond f32's
    /// reach (10^36 m), and all rays then take the f64 ones. (A ray whose origin lies beyond
    /// it, or with a direction component below 10^-20 but not zero, takes them either way.)
    pub fn boxes_in_f32(&self) -> bool {
        self.f32_boxes
    }

    /// Bounds of the whole scene (EMPTY when there are no primitives).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The primitives tagged `object`, in the hierarchy's order (none if it has none). Found
    /// by a binary search: a scene's objects each ask for theirs, and a scan of all
    /// primitives per object would grow as objects × primitives.
    pub fn object_primitives(&self, object: u32) -> impl Iterator<Item = &Primitive> + '_ {
        let fixed = self
            .static_level
            .iter()
            .flat_map(move |s| s.own_object_primitives(object));
        self.own_object_primitives(object).chain(fixed)
    }

    /// [`Bvh::object_primitives`] of this level alone.
    fn own_object_primitives(&self, object: u32) -> impl Iterator<Item = &Primitive> + '_ {
        let tag = |i: &u32| self.primitives[*i as usize].object;
        let start = self.by_object.partition_point(|i| tag(i) < object);
        let end = self.by_object.partition_point(|i| tag(i) <= object);
        self.by_object[start..end]
            .iter()
            .map(|&i| &self.primitives[i as usize])
    }

    /// Bounds of the primitives of scene object `object` (EMPTY if it has none).
    pub fn object_bounds(&self, object: u32) -> Aabb {
        self.object_primitives(object)
            .fold(Aabb::EMPTY, |b, p| b.union(&p.bounds()))
    }

    /// The f64 box test of `ray`.
    fn exact_boxes(&self, ray: &Ray) -> ExactBoxes<'_> {
        ExactBoxes {
            boxes: &self.exact_boxes,
            origin_m: ray.origin_m,
            inv_dir: ray.dir.recip(),
        }
    }

    /// The f32 box test of `ray`, if both it and the tree are within its reach.
    #[inline]
    fn wide_ray(&self, ray: &Ray) -> Option<WideRay<'_>> {
        if self.f32_boxes {
            WideRay::new(&self.nodes, ray)
        } else {
            None
        }
    }

    /// Closest intersection before `t_max_m`; of hits at the same distance, the one on the
    /// primitive of the lowest index ([`Hit::primitive`]; the static level's only when it is
    /// strictly nearer than this level's). That holds wherever the f32 boxes are used (every
    /// scene's tree); the f64 boxes, for trees and rays beyond their reach, carry no margin,
    /// and a box entered within rounding of the best hit may still hide a tie.
    pub fn closest_hit(&self, ray: &Ray, t_max_m: f64) -> Option<Hit> {
        let own = self.own_closest_hit(ray, t_max_m);
        match &self.static_level {
            None => own,
            Some(s) => {
                let reach = own.map_or(t_max_m, |h| h.t_m);
                s.own_closest_hit(ray, reach).or(own)
            }
        }
    }

    /// [`Bvh::closest_hit`] of this level alone.
    #[inline]
    fn own_closest_hit(&self, ray: &Ray, t_max_m: f64) -> Option<Hit> {
        traverse!(self, closest_hit_with, ray, t_max_m, None)
    }

    /// [`Bvh::closest_hit`] with a stack of `N` entries (at least `3 * wide_depth + 4`) and
    /// the box test `boxes`. Children are visited nearest entry first, and a pending one is
    /// dropped once a hit is found before its entry.
    #[inline]
    fn closest_hit_with<const N: usize, B: ChildBoxes>(
        &self,
        ray: &Ray,
        t_max_m: f64,
        boxes: &B,
    ) -> Option<Hit> {
        let mut t_best = TMax::new(t_max_m);
        let mut best: Option<Hit> = None;
        let mut stack = [Pending::default(); N];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let pending = stack[sp];
            if pending.entry_m > t_best.f32_up {
                continue;
            }
            let ni = pending.node as usize;
            let (entry_m, mut mask) = boxes.children(ni, t_best);
            let node = &self.nodes[ni];
            // Leaves met are searched at once; the nodes met are pushed farthest first, so
            // that the nearest is popped next.
            let mut met = [Pending::default(); 4];
            let mut n = 0;
            while mask != 0 {
                let c = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let first = node.first[c] as usize;
                let count = node.count[c] as usize;
                if count == 0 {
                    let mut j = n;
                    while j > 0 && met[j - 1].entry_m < entry_m[c] {
                        met[j] = met[j - 1];
                        j -= 1;
                    }
                    met[j] = Pending {
                        entry_m: entry_m[c],
                        node: node.first[c],
                    };
                    n += 1;
                    continue;
                }
                search_leaf(
                    &self.primitives,
                    first..first + count,
                    ray,
                    &mut best,
                    &mut t_best,
                );
            }
            // One at a time: a slice copy of a variable length is a call to memcpy.
            for &pending in &met[..n] {
                stack[sp] = pending;
                sp += 1;
            }
        }
        best
    }

    /// Whether anything blocks the ray before `t_max_m` (shadow test).
    pub fn any_hit(&self, ray: &Ray, t_max_m: f64) -> bool {
        self.own_any_hit(ray, t_max_m)
            || self
                .static_level
                .as_ref()
                .is_some_and(|s| s.own_any_hit(ray, t_max_m))
    }

    /// [`Bvh::any_hit`] of this level alone.
    #[inline]
    fn own_any_hit(&self, ray: &Ray, t_max_m: f64) -> bool {
        traverse!(self, any_hit_with, ray, t_max_m, false)
    }

    /// [`Bvh::any_hit`] with a stack of `N` node indices (at least `3 * wide_depth + 4`)
    /// and the box test `boxes`. A leaf is tested as soon as its box is met.
    #[inline]
    fn any_hit_with<const N: usize, B: ChildBoxes>(
        &self,
        ray: &Ray,
        t_max_m: f64,
        boxes: &B,
    ) -> bool {
        let t_max = TMax::new(t_max_m);
        let mut stack = [0u32; N];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let ni = stack[sp] as usize;
            let (_, mut mask) = boxes.children(ni, t_max);
            let node = &self.nodes[ni];
            while mask != 0 {
                let c = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let first = node.first[c] as usize;
                let count = node.count[c] as usize;
                if count == 0 {
                    stack[sp] = node.first[c];
                    sp += 1;
                } else if self.primitives[first..first + count]
                    .iter()
                    .any(|p| p.intersect(ray, t_max_m).is_some())
                {
                    return true;
                }
            }
        }
        false
    }
}

/// The 4-wide tree of a binary one (`nodes[0]` its root): each node takes the binary node's
/// children and replaces the one with the largest surface that is not a leaf by its two
/// children until it has four. Returns the nodes (their boxes not yet set: [`refit`]) and the
/// depth. A child's node always comes after its parent's.
fn collapse(binary: &[BinaryNode], num_primitives: usize) -> (Vec<WideNode>, usize) {
    // At most one node per interior binary node: reserved once (pages only touched as used).
    let mut wide = Vec::with_capacity(num_primitives.max(1));
    wide.push(WideNode::EMPTY);
    let mut depth = 0;
    let mut stack = vec![(0usize, 0usize, 0usize)];
    while let Some((b, w, d)) = stack.pop() {
        depth = depth.max(d);
        // A root that is a leaf is the single child of the wide root.
        let mut children = [0usize; 4];
        let mut len = if binary[b].count > 0 {
            children[0] = b;
            1
        } else {
            children[0] = binary[b].first as usize;
            children[1] = children[0] + 1;
            2
        };
        while len < 4 {
            // The interior child with the largest surface (the first of equals).
            let mut widest: Option<(usize, f64)> = None;
            for (i, &c) in children[..len].iter().enumerate() {
                let area = binary[c].area_m2;
                if binary[c].count == 0 && widest.is_none_or(|(_, a)| area > a) {
                    widest = Some((i, area));
                }
            }
            let Some((i, _)) = widest else { break };
            let l = binary[children[i]].first as usize;
            children.copy_within(i + 1..len, i + 2);
            children[i] = l;
            children[i + 1] = l + 1;
            len += 1;
        }
        for (lane, &c) in children[..len].iter().enumerate() {
            if binary[c].count > 0 {
                wide[w].first[lane] = binary[c].first;
                wide[w].count[lane] = binary[c].count;
            } else {
                let child = wide.len();
                wide.push(WideNode::EMPTY);
                wide[w].first[lane] = child as u32;
                stack.push((c, child, d + 1));
            }
        }
    }
    wide.shrink_to_fit();
    (wide, depth)
}

/// The positions of `primitives` grouped by object, ascending within each: a counting sort
/// when the object indices are few (as a scene's are), else a stable sort.
fn grouped_by_object(primitives: &[Primitive]) -> Vec<u32> {
    let objects: Vec<u32> = primitives.par_iter().map(|p| p.object).collect();
    let num_objects = objects.par_iter().max().map_or(0, |&o| o as usize + 1);
    if num_objects > objects.len() {
        let mut grouped: Vec<u32> = (0..objects.len() as u32).collect();
        grouped.par_sort_by_key(|&i| objects[i as usize]);
        return grouped;
    }
    let mut starts = vec![0u32; num_objects + 1];
    for &o in &objects {
        starts[o as usize + 1] += 1;
    }
    for k in 1..starts.len() {
        starts[k] += starts[k - 1];
    }
    let mut grouped = vec![0u32; objects.len()];
    for (i, &o) in objects.iter().enumerate() {
        let at = &mut starts[o as usize];
        grouped[*at as usize] = i as u32;
        *at += 1;
    }
    grouped
}

/// Sets every child's box of the 4-wide tree from its `primitives` (in the tree's order): the
/// exact f64 boxes, returned, and the f32 planes rounded outward from them. Leaves first, in
/// parallel; then interior children from their nodes' boxes, last node first (a child's
/// node comes after its parent's).
fn refit(wide: &mut [WideNode], primitives: &[Primitive]) -> Vec<[Aabb; 4]> {
    let mut exact = vec![[Aabb::EMPTY; 4]; wide.len()];
    exact
        .par_iter_mut()
        .zip(wide.par_iter())
        .with_min_len(256)
        .for_each(|(boxes, node)| {
            for lane in 0..4 {
                let (first, count) = (node.first[lane] as usize, node.count[lane] as usize);
                if count > 0 {
                    boxes[lane] = primitives[first..first + count]
                        .iter()
                        .fold(Aabb::EMPTY, |b, p| b.union(&p.bounds()));
                }
            }
        });
    for w in (0..wide.len()).rev() {
        let (head, tail) = exact.split_at_mut(w + 1);
        for lane in 0..4 {
            let node = &wide[w];
            if node.count[lane] == 0 && node.first[lane] != 0 {
                let child = &tail[node.first[lane] as usize - w - 1];
                head[w][lane] = child.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
            }
        }
    }
    set_planes(wide, &exact);
    exact
}

/// Sets each node's f32 planes from its children's `exact` boxes, rounded outward.
fn set_planes(wide: &mut [WideNode], exact: &[[Aabb; 4]]) {
    wide.par_iter_mut()
        .zip(exact.par_iter())
        .with_min_len(256)
        .for_each(|(node, boxes)| {
            for (lane, b) in boxes.iter().enumerate() {
                for axis in 0..3 {
                    node.planes[2 * axis][lane] = f32_down(b.min[axis]);
                    node.planes[2 * axis + 1][lane] = f32_up(b.max[axis]);
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PrimitiveKind;

    /// The nearest hit of `ray` among `primitives`, by testing every one.
    fn brute_force(primitives: &[Primitive], ray: &Ray) -> Option<(u32, f64)> {
        primitives
            .iter()
            .filter_map(|p| p.intersect(ray, f64::INFINITY).map(|(t, _)| (p.object, t)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Grouping by object, counted or sorted, is the stable sort by object index.
    #[test]
    fn grouped_by_object_is_the_stable_sort() {
        for spread in [7u32, 1 << 30] {
            let primitives: Vec<Primitive> = (0..500u32)
                .map(|i| Primitive {
                    kind: PrimitiveKind::Sphere {
                        centre: DVec3::ZERO,
                        radius_m: 1.0,
                    },
                    object: (i * 7919 % 13) * (spread / 7),
                })
                .collect();
            let mut expected: Vec<u32> = (0..500).collect();
            expected.sort_by_key(|&i| primitives[i as usize].object);
            assert_eq!(grouped_by_object(&primitives), expected, "spread {spread}");
        }
    }

    /// A binary tree made by hand: a chain one level per sphere (sphere k the leaf beside
    /// the node of spheres k + 1..), as deep as any build may make (`MAX_DEPTH`), with spheres
    /// centred at `scale`·(k + 1)^2 m on the x axis. The build's binning never makes chains
    /// this long in f32, so the traversal's full stack is tested on this tree, with f32
    /// boxes and (`scale` beyond their reach) with f64 ones: every query finds what brute
    /// force finds.
    #[test]
    fn hand_made_chain_as_deep_as_allowed_matches_brute_force() {
        for scale in [1.0, 1e33] {
            let n = MAX_DEPTH + 1;
            let centre = |k: usize| scale * ((k + 1) * (k + 1)) as f64;
            let primitives: Vec<Primitive> = (0..n)
                .map(|k| Primitive {
                    kind: PrimitiveKind::Sphere {
                        centre: DVec3::new(centre(k), 0.0, 0.0),
                        radius_m: 0.25 * scale,
                    },
                    object: k as u32,
                })
                .collect();
            // Interior node k at slot 2k (k < n − 1) has children at slots 2k + 1 (the leaf
            // of sphere k) and 2k + 2 (interior node k + 1, or sphere n − 1's leaf).
            let mut nodes = vec![BinaryNode::default(); 2 * n - 1];
            for k in 0..n - 1 {
                nodes[2 * k] = BinaryNode {
                    area_m2: (n - k) as f64,
                    first: (2 * k + 1) as u32,
                    count: 0,
                };
                nodes[2 * k + 1] = BinaryNode {
                    area_m2: 1.0,
                    first: k as u32,
                    count: 1,
                };
            }
            nodes[2 * n - 2] = BinaryNode {
                area_m2: 1.0,
                first: (n - 1) as u32,
                count: 1,
            };
            let tree = BinaryTree {
                nodes,
                order: (0..n as u32).collect(),
                depth: n - 1,
            };
            let bvh = Bvh::from_tree(primitives.clone(), tree);
            assert_eq!(
                bvh.boxes_in_f32(),
                scale < F32_REACH_M / 1e5,
                "scale {scale}"
            );
            assert!(bvh.wide_depth() > SHALLOW_DEPTH, "{}", bvh.wide_depth());
            for k in 0..n {
                let origin = DVec3::new(centre(k) - 0.5 * scale, 0.01 * scale, 0.0);
                for dir in [DVec3::X, -DVec3::X] {
                    let ray = Ray::new(origin, dir);
                    let hit = bvh.closest_hit(&ray, f64::INFINITY);
                    let expected = brute_force(&primitives, &ray);
                    assert_eq!(
                        hit.map(|h| (h.object, h.t_m)),
                        expected,
                        "scale {scale}, {ray:?}"
                    );
                    if let Some((_, t)) = expected {
                        assert!(bvh.any_hit(&ray, t * (1.0 + 1e-9)));
                        assert!(!bvh.any_hit(&ray, t * (1.0 - 1e-9)));
                    }
                }
            }
        }
    }
}
