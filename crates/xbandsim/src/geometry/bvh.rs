//! Bounding-volume hierarchy with binned SAH construction and stack traversal.
//!
//! Why our own BVH rather than a crate: our primitives are exact analytic shapes (spheres,
//! cylinders, disks, parallelograms) mixed with triangles, and SBR needs f64 hit distances
//! for the carrier phase. A small, allocation-free traversal over an enum of primitives does
//! that directly; `benches/raycast.rs` measures it against brute force (docs/performance.md).

use super::{Aabb, Hit, Primitive, Ray};
use glam::DVec3;

const NUM_BINS: usize = 16;
const MAX_LEAF_SIZE: usize = 4;
/// Below this depth nodes are split at the SAH's best plane; from it on, at the median of the
/// widest axis of their centres, which halves the count each level. So no leaf is deeper
/// than `SAH_MAX_DEPTH + 32` for up to 2^31 primitives (node indices are `u32`), however unbalanced the SAH's splits
/// are (primitives spaced geometrically make it peel one off per level).
const SAH_MAX_DEPTH: usize = 64;
/// A traversal holds at most one pending node per level plus the one being visited, so this
/// bounds the stack of every tree `build` makes (`SAH_MAX_DEPTH + 32 + 1` entries at most).
const TRAVERSAL_STACK: usize = 128;
const _: () = assert!(SAH_MAX_DEPTH + 32 < TRAVERSAL_STACK);
/// The stack of a traversal of a tree no deeper than `SHALLOW_STACK - 1` (every tree of a
/// dataset scene): a stack of this size is cleared on each query, not `TRAVERSAL_STACK`'s.
const SHALLOW_STACK: usize = 32;

#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Aabb,
    /// Interior: index of the left child (right = left + 1). Leaf: first primitive.
    first: u32,
    /// Number of primitives in a leaf; 0 for an interior node.
    count: u32,
}

/// A BVH owning its (reordered) primitives.
#[derive(Debug, Clone)]
pub struct Bvh {
    nodes: Vec<Node>,
    primitives: Vec<Primitive>,
    /// Indices into `primitives`, sorted by object tag and, within one object, ascending:
    /// an object's primitives without a scan of everyone's.
    by_object: Vec<u32>,
    /// Depth of the deepest node (the root's is 0): a traversal's stack holds at most
    /// `max_depth + 1` entries.
    max_depth: usize,
}

impl Bvh {
    /// Builds the hierarchy over `primitives` (order is not kept).
    pub fn build(mut primitives: Vec<Primitive>) -> Self {
        if primitives.is_empty() {
            return Bvh {
                nodes: Vec::new(),
                primitives,
                by_object: Vec::new(),
                max_depth: 0,
            };
        }
        let bounds: Vec<Aabb> = primitives.iter().map(|p| p.bounds()).collect();
        let centres: Vec<DVec3> = bounds.iter().map(|b| b.centre()).collect();
        let mut order: Vec<u32> = (0..primitives.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * primitives.len());
        nodes.push(Node {
            bounds: Aabb::EMPTY,
            first: 0,
            count: primitives.len() as u32,
        });
        let mut stack = vec![(0usize, 0usize)];
        let mut max_depth = 0;
        while let Some((ni, depth)) = stack.pop() {
            max_depth = max_depth.max(depth);
            let first = nodes[ni].first as usize;
            let count = nodes[ni].count as usize;
            let slice = &mut order[first..first + count];
            let mut nb = Aabb::EMPTY;
            let mut cb = Aabb::EMPTY;
            for &i in slice.iter() {
                nb = nb.union(&bounds[i as usize]);
                cb.grow(centres[i as usize]);
            }
            nodes[ni].bounds = nb;
            if count <= MAX_LEAF_SIZE {
                continue;
            }
            let (axis, mut left) = if depth < SAH_MAX_DEPTH {
                let Some((axis, split_pos)) = best_split(slice, &bounds, &centres, &cb, &nb) else {
                    continue;
                };
                let mut left = 0;
                for j in 0..slice.len() {
                    if centres[slice[j] as usize][axis] < split_pos {
                        slice.swap(left, j);
                        left += 1;
                    }
                }
                (axis, left)
            } else {
                ((cb.max - cb.min).max_position(), 0)
            };
            if left == 0 || left == count {
                left = count / 2;
                slice.sort_by(|a, b| {
                    centres[*a as usize][axis].total_cmp(&centres[*b as usize][axis])
                });
            }
            let li = nodes.len();
            nodes.push(Node {
                bounds: Aabb::EMPTY,
                first: first as u32,
                count: left as u32,
            });
            nodes.push(Node {
                bounds: Aabb::EMPTY,
                first: (first + left) as u32,
                count: (count - left) as u32,
            });
            nodes[ni].first = li as u32;
            nodes[ni].count = 0;
            stack.push((li, depth + 1));
            stack.push((li + 1, depth + 1));
        }
        let reordered: Vec<Primitive> = order.iter().map(|&i| primitives[i as usize]).collect();
        primitives.clear();
        let mut by_object: Vec<u32> = (0..reordered.len() as u32).collect();
        // Stable: within one object the indices stay ascending.
        by_object.sort_by_key(|&i| reordered[i as usize].object);
        Bvh {
            nodes,
            primitives: reordered,
            by_object,
            max_depth,
        }
    }

    /// The primitives, in the hierarchy's order (hit indices refer to this order).
    pub fn primitives(&self) -> &[Primitive] {
        &self.primitives
    }

    /// Number of nodes.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Levels below the root of the deepest leaf (0 for a single leaf or an empty tree).
    pub fn depth(&self) -> usize {
        self.max_depth
    }

    /// Bounds of the whole scene (EMPTY when there are no primitives).
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    /// The primitives tagged `object`, in the hierarchy's order (none if it has none). Found
    /// by a binary search: a scene's objects each ask for theirs, and a scan of all
    /// primitives per object would grow as objects × primitives.
    pub fn object_primitives(&self, object: u32) -> impl Iterator<Item = &Primitive> + '_ {
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

    /// Closest intersection before `t_max_m`.
    pub fn closest_hit(&self, ray: &Ray, t_max_m: f64) -> Option<Hit> {
        if self.max_depth < SHALLOW_STACK {
            self.closest_hit_with::<SHALLOW_STACK>(ray, t_max_m)
        } else {
            self.closest_hit_with::<TRAVERSAL_STACK>(ray, t_max_m)
        }
    }

    /// [`Bvh::closest_hit`] with a stack of `N` entries (more than `max_depth`).
    #[inline]
    fn closest_hit_with<const N: usize>(&self, ray: &Ray, t_max_m: f64) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let inv = ray.dir.recip();
        let mut t_best = t_max_m;
        let mut best: Option<Hit> = None;
        let mut stack = [0u32; N];
        let mut sp = 0usize;
        self.nodes[0]
            .bounds
            .hit_distance(ray.origin_m, inv, t_best)?;
        stack[sp] = 0;
        sp += 1;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            if node.count > 0 {
                let first = node.first as usize;
                for (k, p) in self.primitives[first..first + node.count as usize]
                    .iter()
                    .enumerate()
                {
                    if let Some((t, n)) = p.intersect(ray, t_best) {
                        t_best = t;
                        best = Some(Hit {
                            t_m: t,
                            normal: n,
                            primitive: (first + k) as u32,
                            object: p.object,
                        });
                    }
                }
                continue;
            }
            let l = node.first as usize;
            let dl = self.nodes[l].bounds.hit_distance(ray.origin_m, inv, t_best);
            let dr = self.nodes[l + 1]
                .bounds
                .hit_distance(ray.origin_m, inv, t_best);
            match (dl, dr) {
                (Some(a), Some(b)) => {
                    // Never more than max_depth + 1 entries: one pending sibling per level.
                    let (near, far) = if a <= b { (l, l + 1) } else { (l + 1, l) };
                    stack[sp] = far as u32;
                    stack[sp + 1] = near as u32;
                    sp += 2;
                }
                (Some(_), None) => {
                    stack[sp] = l as u32;
                    sp += 1;
                }
                (None, Some(_)) => {
                    stack[sp] = (l + 1) as u32;
                    sp += 1;
                }
                (None, None) => {}
            }
        }
        best
    }

    /// Whether anything blocks the ray before `t_max_m` (shadow test).
    pub fn any_hit(&self, ray: &Ray, t_max_m: f64) -> bool {
        if self.max_depth < SHALLOW_STACK {
            self.any_hit_with::<SHALLOW_STACK>(ray, t_max_m)
        } else {
            self.any_hit_with::<TRAVERSAL_STACK>(ray, t_max_m)
        }
    }

    /// [`Bvh::any_hit`] with a stack of `N` entries (more than `max_depth`).
    #[inline]
    fn any_hit_with<const N: usize>(&self, ray: &Ray, t_max_m: f64) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inv = ray.dir.recip();
        let mut stack = [0u32; N];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            if node
                .bounds
                .hit_distance(ray.origin_m, inv, t_max_m)
                .is_none()
            {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                if self.primitives[first..first + node.count as usize]
                    .iter()
                    .any(|p| p.intersect(ray, t_max_m).is_some())
                {
                    return true;
                }
                continue;
            }
            stack[sp] = node.first;
            stack[sp + 1] = node.first + 1;
            sp += 2;
        }
        false
    }
}

/// Binned SAH: the axis and split position with the lowest cost, if any beats a leaf.
fn best_split(
    slice: &[u32],
    bounds: &[Aabb],
    centres: &[DVec3],
    centre_bounds: &Aabb,
    node_bounds: &Aabb,
) -> Option<(usize, f64)> {
    let mut best: Option<(f64, usize, f64)> = None;
    for axis in 0..3 {
        let lo = centre_bounds.min[axis];
        let hi = centre_bounds.max[axis];
        if hi - lo <= 1e-12 {
            continue;
        }
        let mut bin_bounds = [Aabb::EMPTY; NUM_BINS];
        let mut bin_counts = [0usize; NUM_BINS];
        let scale = NUM_BINS as f64 / (hi - lo);
        for &i in slice {
            let b = (((centres[i as usize][axis] - lo) * scale) as usize).min(NUM_BINS - 1);
            bin_counts[b] += 1;
            bin_bounds[b] = bin_bounds[b].union(&bounds[i as usize]);
        }
        let mut left_area = [0.0; NUM_BINS];
        let mut left_count = [0usize; NUM_BINS];
        let mut acc = Aabb::EMPTY;
        let mut n = 0;
        for b in 0..NUM_BINS - 1 {
            acc = acc.union(&bin_bounds[b]);
            n += bin_counts[b];
            left_area[b] = acc.surface_area();
            left_count[b] = n;
        }
        let mut acc = Aabb::EMPTY;
        let mut n = 0;
        for b in (1..NUM_BINS).rev() {
            acc = acc.union(&bin_bounds[b]);
            n += bin_counts[b];
            let cost = left_area[b - 1] * left_count[b - 1] as f64 + acc.surface_area() * n as f64;
            if left_count[b - 1] > 0 && n > 0 && best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, lo + b as f64 / scale));
            }
        }
    }
    let (cost, axis, pos) = best?;
    let leaf_cost = node_bounds.surface_area() * slice.len() as f64;
    (cost < leaf_cost || slice.len() > 16).then_some((axis, pos))
}
