//! Packet traversal: the closest hits of coherent rays searched together through the 4-wide
//! tree (Wald, Slusallek, Benthin & Wagner, "Interactive rendering with coherent ray
//! tracing", Computer Graphics Forum 20(3), 2001), with whole-packet culling by interval
//! arithmetic (Boulos et al., "Geometric and arithmetic culling methods for entire ray
//! packets", University of Utah UUCS-06-010, 2006). docs/architecture.md, "The ray caster".
//!
//! The rays of a scan column share their origin and nearly their direction: they meet the
//! same boxes, and mostly none. A set of rays is first tested against the root's children at
//! once ([`PacketBounds`]: every operand of the box test bounded over the rays), then each
//! packet of [`PACKET_RAYS`] consecutive rays is searched together: a node is popped once
//! for all of them, its four children tested for the whole packet the same way and, where
//! the packet may meet one, for each ray in lane loops over `[f32; 8]` ([`PacketRays`]),
//! which the compiler turns into AVX2 (or SSE2) code. Each ray's own test is the single-ray
//! one ([`WideRay`](super::WideRay)) lane for lane: the same f32 arithmetic, rounded outward
//! the same way, so it culls only boxes that ray cannot meet before its best hit so far; the
//! packet's test bounds every ray's. A leaf's primitives are then intersected in f64, one
//! ray at a time, for the rays that met its box. With the closest hit defined as the least
//! (distance, primitive index) pair ([`tie_reach`](super::tie_reach)), the hits are exactly
//! those of [`Bvh::closest_hit`], whatever order the packet meets the leaves in.

use super::{
    lanes_met, search_leaf, Bvh, Pending, TMax, WideNode, F32_EPSILON_HALF_UP, F32_MIN_DIRECTION,
    F32_REACH_M, SHALLOW_DEPTH, SHALLOW_STACK, TRAVERSAL_STACK,
};
use crate::geometry::{Hit, Ray};

/// The rays a packet traces together: eight f32 lanes, one AVX2 register.
pub const PACKET_RAYS: usize = 8;

/// A ray's origin along one axis rounded to f32 and moved by one unit in its last place (and
/// never by zero) toward `sign`'s side (see [`WideRay`](super::WideRay)).
#[inline(always)]
fn origin_moved(o: f64, sign: f32) -> f32 {
    let f = o as f32;
    f + (f.abs() * F32_EPSILON_HALF_UP + f32::MIN_POSITIVE).copysign(sign)
}

/// The bounds over a packet's rays of each operand of the box test ([`PacketRays`]), for the
/// test of the whole packet at once ([`PacketBounds::children`]).
struct PacketBounds {
    /// Per axis, where every ray's direction has the same sign and is not zero (None
    /// elsewhere: the axis then culls nothing).
    axes: [Option<AxisBounds>; 3],
}

/// The bounds over a packet's rays of one axis's operands of the box test.
#[derive(Debug, Clone, Copy)]
struct AxisBounds {
    /// The plane a ray enters by: 0 the minimum, 1 the maximum (negative directions).
    near_plane: usize,
    /// The least and greatest of the rays' near origins, far origins and reciprocal
    /// directions.
    near_origin: [f32; 2],
    far_origin: [f32; 2],
    inv_dir: [f32; 2],
}

impl PacketBounds {
    /// The bounds of `rays` (any number, at least one), from the coordinates' own: each
    /// operand of [`PacketRays`] is a monotonic function of one coordinate (rounding to f32
    /// is monotonic; so are the origin's move toward the direction's sign and the reciprocal
    /// over one sign), so its bounds are its values at the coordinate's bounds. None when a
    /// ray is beyond the f32 test's reach (far origin, a direction component below 10^-20
    /// but not zero, a NaN).
    #[inline]
    fn new(rays: &[Ray]) -> Option<PacketBounds> {
        let first = rays.first()?;
        let (mut o_lo, mut o_hi) = (first.origin_m.to_array(), first.origin_m.to_array());
        let (mut d_lo, mut d_hi) = (first.dir.to_array(), first.dir.to_array());
        let mut reach = true;
        for ray in rays {
            for axis in 0..3 {
                let (o, d) = (ray.origin_m[axis], ray.dir[axis]);
                let d_abs = d.abs();
                // (NaN fails both.)
                reach &= o.abs() < F32_REACH_M && (d_abs == 0.0 || d_abs >= F32_MIN_DIRECTION);
                o_lo[axis] = if o < o_lo[axis] { o } else { o_lo[axis] };
                o_hi[axis] = if o > o_hi[axis] { o } else { o_hi[axis] };
                d_lo[axis] = if d < d_lo[axis] { d } else { d_lo[axis] };
                d_hi[axis] = if d > d_hi[axis] { d } else { d_hi[axis] };
            }
        }
        if !reach {
            return None;
        }
        let mut axes = [None; 3];
        for (axis, bounds) in axes.iter_mut().enumerate() {
            if d_lo[axis] > 0.0 || d_hi[axis] < 0.0 {
                // The reciprocal falls as the direction grows, over either sign.
                let inv_dir = [1.0 / (d_hi[axis] as f32), 1.0 / (d_lo[axis] as f32)];
                let sign = inv_dir[0];
                *bounds = Some(AxisBounds {
                    near_plane: usize::from(sign < 0.0),
                    near_origin: [
                        origin_moved(o_lo[axis], sign),
                        origin_moved(o_hi[axis], sign),
                    ],
                    far_origin: [
                        origin_moved(o_lo[axis], -sign),
                        origin_moved(o_hi[axis], -sign),
                    ],
                    inv_dir,
                });
            }
        }
        Some(PacketBounds { axes })
    }

    /// The children of `node` that some ray may meet before `t_max_up` (the largest of the
    /// rays' search distances, f32 rounded up), as a lane mask: the box test of a ray whose
    /// every operand may be anywhere within the packet's bounds (interval arithmetic: Boulos
    /// et al., "Geometric and arithmetic culling methods for entire ray packets", University
    /// of Utah UUCS-06-010, 2006). Each bound is a bound of the same rounded operation on a
    /// ray's own operands (rounding is monotonic), so a child it rejects is one that every
    /// ray's own test rejects.
    #[inline(always)]
    fn children(&self, node: &WideNode, t_max_up: f32) -> u32 {
        let mut entry = [0f32; 4];
        let mut exit = [f32::INFINITY; 4];
        for (axis, bounds) in self.axes.iter().enumerate() {
            let Some(b) = bounds else { continue };
            let near = &node.planes[2 * axis + b.near_plane];
            let far = &node.planes[2 * axis + 1 - b.near_plane];
            let [inv_lo, inv_hi] = b.inv_dir;
            for c in 0..4 {
                // The least of the four corner products, and the greatest (no NaN: the
                // reciprocals are finite and not zero, the origins finite).
                let (lo, hi) = (near[c] - b.near_origin[1], near[c] - b.near_origin[0]);
                let t_near = least(
                    least(lo * inv_lo, lo * inv_hi),
                    least(hi * inv_lo, hi * inv_hi),
                );
                let (lo, hi) = (far[c] - b.far_origin[1], far[c] - b.far_origin[0]);
                let t_far = greatest(
                    greatest(lo * inv_lo, lo * inv_hi),
                    greatest(hi * inv_lo, hi * inv_hi),
                );
                entry[c] = if t_near > entry[c] { t_near } else { entry[c] };
                exit[c] = if t_far < exit[c] { t_far } else { exit[c] };
            }
        }
        lanes_met(&mut entry, &exit, &[t_max_up; 4])
    }
}

/// The lesser of two numbers that are not NaN (a compare and a select).
#[inline(always)]
fn least(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// The greater of two numbers that are not NaN.
#[inline(always)]
fn greatest(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// The rays of a packet prepared for each one's own f32 box test, one lane per ray (see
/// [`WideRay`](super::WideRay) for the rounding of the origins). A lane without a ray repeats
/// the first ray and is given a search distance of −∞, so that it meets no box.
struct PacketRays {
    /// All bits set where the ray's direction is negative along the axis (its near plane is
    /// the box's maximum), none elsewhere: a lane select by bit masks.
    negative: [[u32; PACKET_RAYS]; 3],
    near_origin: [[f32; PACKET_RAYS]; 3],
    far_origin: [[f32; PACKET_RAYS]; 3],
    inv_dir: [[f32; PACKET_RAYS]; 3],
}

impl PacketRays {
    /// The lanes of up to [`PACKET_RAYS`] rays within the f32 test's reach.
    #[inline]
    fn new(rays: &[Ray]) -> PacketRays {
        let mut packet = PacketRays {
            negative: [[0; PACKET_RAYS]; 3],
            near_origin: [[0.0; PACKET_RAYS]; 3],
            far_origin: [[0.0; PACKET_RAYS]; 3],
            inv_dir: [[0.0; PACKET_RAYS]; 3],
        };
        for lane in 0..PACKET_RAYS {
            let ray = rays.get(lane).unwrap_or(&rays[0]);
            for axis in 0..3 {
                let (o, d) = (ray.origin_m[axis], ray.dir[axis]);
                let inv = 1.0 / (d as f32);
                packet.negative[axis][lane] = if inv < 0.0 { u32::MAX } else { 0 };
                packet.inv_dir[axis][lane] = inv;
                packet.near_origin[axis][lane] = origin_moved(o, inv);
                packet.far_origin[axis][lane] = origin_moved(o, -inv);
            }
        }
        packet
    }

    /// For each child of `node` in `children` (a lane mask): the rays (a bit per lane) that
    /// may meet its box before their `t_max_up` (f32, rounded up), and a lower bound on each
    /// one's entry distance; the other children are met by no ray.
    #[inline(always)]
    fn children(
        &self,
        node: &WideNode,
        children: u32,
        t_max_up: &[f32; PACKET_RAYS],
    ) -> ([[f32; PACKET_RAYS]; 4], [u32; 4]) {
        let mut entries = [[0f32; PACKET_RAYS]; 4];
        let mut masks = [0u32; 4];
        let mut todo = children;
        while todo != 0 {
            let c = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let mut entry = [0f32; PACKET_RAYS];
            let mut exit = [f32::INFINITY; PACKET_RAYS];
            for axis in 0..3 {
                let lo = node.planes[2 * axis][c].to_bits();
                let hi = node.planes[2 * axis + 1][c].to_bits();
                let negative = &self.negative[axis];
                let (near_o, far_o, inv) = (
                    &self.near_origin[axis],
                    &self.far_origin[axis],
                    &self.inv_dir[axis],
                );
                for r in 0..PACKET_RAYS {
                    let neg = negative[r];
                    let near_plane = f32::from_bits((hi & neg) | (lo & !neg));
                    let far_plane = f32::from_bits((lo & neg) | (hi & !neg));
                    let t_near = (near_plane - near_o[r]) * inv[r];
                    let t_far = (far_plane - far_o[r]) * inv[r];
                    // Compare-and-select: a NaN distance leaves the bound as it was.
                    entry[r] = if t_near > entry[r] { t_near } else { entry[r] };
                    exit[r] = if t_far < exit[r] { t_far } else { exit[r] };
                }
            }
            masks[c] = lanes_met(&mut entry, &exit, t_max_up);
            entries[c] = entry;
        }
        (entries, masks)
    }
}

/// A pending node of a packet's search: the least entry distance of its rays, and which rays.
#[derive(Debug, Clone, Copy, Default)]
struct PacketPending {
    pending: Pending,
    rays: u32,
}

impl Bvh {
    /// The closest hits of many rays: `hits[i]` is [`Bvh::closest_hit`]`(&rays[i],
    /// t_max_m[i])`, the same hit to the bit. The whole set is first tested against the
    /// root's children at once (a scan column that misses every object costs one test), then
    /// searched in packets of [`PACKET_RAYS`] consecutive rays, each first tested at once
    /// too. This pays when neighbours are coherent (a scan column, a row of tubes); a packet
    /// with a ray beyond the f32 test's reach is searched one ray at a time.
    ///
    /// # Panics
    /// If the three slices differ in length.
    pub fn closest_hits(&self, rays: &[Ray], t_max_m: &[f64], hits: &mut [Option<Hit>]) {
        assert!(
            rays.len() == t_max_m.len() && rays.len() == hits.len(),
            "closest_hits: {} rays, {} distances, {} hits",
            rays.len(),
            t_max_m.len(),
            hits.len()
        );
        let Some(s) = &self.static_level else {
            self.own_closest_hits(rays, t_max_m, hits);
            return;
        };
        for ((rays, t_max_m), hits) in rays
            .chunks(PACKET_RAYS)
            .zip(t_max_m.chunks(PACKET_RAYS))
            .zip(hits.chunks_mut(PACKET_RAYS))
        {
            self.own_closest_hits(rays, t_max_m, hits);
            let mut reach = [0.0; PACKET_RAYS];
            for (r, (h, t)) in hits.iter().zip(t_max_m).enumerate() {
                reach[r] = h.map_or(*t, |h| h.t_m);
            }
            let mut nearer = [None; PACKET_RAYS];
            let n = rays.len();
            s.own_closest_hits(rays, &reach[..n], &mut nearer[..n]);
            for (h, s) in hits.iter_mut().zip(&nearer[..n]) {
                if s.is_some() {
                    *h = *s;
                }
            }
        }
    }

    /// [`Bvh::closest_hits`] of this level alone.
    fn own_closest_hits(&self, rays: &[Ray], t_max_m: &[f64], hits: &mut [Option<Hit>]) {
        if self.nodes.is_empty() || rays.is_empty() {
            hits.fill(None);
            return;
        }
        if !self.f32_boxes {
            self.single_closest_hits(rays, t_max_m, hits);
            return;
        }
        if rays.len() > PACKET_RAYS && self.misses_root(rays, t_max_m) == Some(true) {
            hits.fill(None);
            return;
        }
        for ((rays, t_max_m), hits) in rays
            .chunks(PACKET_RAYS)
            .zip(t_max_m.chunks(PACKET_RAYS))
            .zip(hits.chunks_mut(PACKET_RAYS))
        {
            match self.misses_root(rays, t_max_m) {
                Some(true) => hits.fill(None),
                None => self.single_closest_hits(rays, t_max_m, hits),
                Some(false) => {
                    let Some(bounds) = PacketBounds::new(rays) else {
                        unreachable!("the rays were found within reach")
                    };
                    let packet = PacketRays::new(rays);
                    if self.wide_depth <= SHALLOW_DEPTH {
                        self.packet_closest_hits::<SHALLOW_STACK>(
                            &packet, &bounds, rays, t_max_m, hits,
                        );
                    } else {
                        self.packet_closest_hits::<TRAVERSAL_STACK>(
                            &packet, &bounds, rays, t_max_m, hits,
                        );
                    }
                }
            }
        }
    }

    /// Whether every one of `rays` misses every child of the root before its search distance
    /// (tested at once: [`PacketBounds::children`]); None when one is beyond the f32 test's
    /// reach.
    #[inline]
    fn misses_root(&self, rays: &[Ray], t_max_m: &[f64]) -> Option<bool> {
        let bounds = PacketBounds::new(rays)?;
        let mut t_max = f64::NEG_INFINITY;
        for &t in t_max_m {
            // (A NaN distance is never the largest: its ray meets nothing.)
            t_max = if t > t_max { t } else { t_max };
        }
        Some(bounds.children(&self.nodes[0], TMax::new(t_max).f32_up) == 0)
    }

    /// [`Bvh::own_closest_hit`] of each ray.
    fn single_closest_hits(&self, rays: &[Ray], t_max_m: &[f64], hits: &mut [Option<Hit>]) {
        for ((ray, &t), hit) in rays.iter().zip(t_max_m).zip(hits.iter_mut()) {
            *hit = self.own_closest_hit(ray, t);
        }
    }

    /// The packet search with a stack of `N` entries (at least `3 * wide_depth + 4`, as a
    /// single ray's): children are pushed nearest least entry last, and a node is dropped
    /// once every one of its rays has a hit before its least entry.
    #[inline]
    fn packet_closest_hits<const N: usize>(
        &self,
        packet: &PacketRays,
        bounds: &PacketBounds,
        rays: &[Ray],
        t_max_m: &[f64],
        hits: &mut [Option<Hit>],
    ) {
        let mut t_best = [TMax {
            m: f64::NEG_INFINITY,
            f32_up: f32::NEG_INFINITY,
        }; PACKET_RAYS];
        let mut t_best_up = [f32::NEG_INFINITY; PACKET_RAYS];
        let mut best: [Option<Hit>; PACKET_RAYS] = [None; PACKET_RAYS];
        for (r, &t) in t_max_m.iter().enumerate() {
            t_best[r] = TMax::new(t);
            t_best_up[r] = t_best[r].f32_up;
        }
        let mut stack = [PacketPending::default(); N];
        stack[0].rays = (1u32 << rays.len()) - 1;
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let PacketPending {
                pending,
                rays: node_rays,
            } = stack[sp];
            // The rays whose best hit so far is not before the node's least entry.
            let mut live = 0u32;
            for (r, &up) in t_best_up.iter().enumerate() {
                live |= u32::from(pending.entry_m <= up) << r;
            }
            let live = live & node_rays;
            if live == 0 {
                continue;
            }
            let node = &self.nodes[pending.node as usize];
            let mut t_max_up = f32::NEG_INFINITY;
            for (r, &up) in t_best_up.iter().enumerate() {
                if live & (1 << r) != 0 && up > t_max_up {
                    t_max_up = up;
                }
            }
            let children = bounds.children(node, t_max_up);
            if children == 0 {
                continue;
            }
            let (entries, masks) = packet.children(node, children, &t_best_up);
            let mut met = [PacketPending::default(); 4];
            let mut n = 0;
            for c in 0..4 {
                let mut lanes = masks[c] & live;
                if lanes == 0 {
                    continue;
                }
                let first = node.first[c] as usize;
                let count = node.count[c] as usize;
                if count == 0 {
                    let mut entry_m = f32::INFINITY;
                    let mut l = lanes;
                    while l != 0 {
                        let r = l.trailing_zeros() as usize;
                        l &= l - 1;
                        entry_m = entry_m.min(entries[c][r]);
                    }
                    let mut j = n;
                    while j > 0 && met[j - 1].pending.entry_m < entry_m {
                        met[j] = met[j - 1];
                        j -= 1;
                    }
                    met[j] = PacketPending {
                        pending: Pending {
                            entry_m,
                            node: node.first[c],
                        },
                        rays: lanes,
                    };
                    n += 1;
                    continue;
                }
                while lanes != 0 {
                    let r = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    search_leaf(
                        &self.primitives,
                        first..first + count,
                        &rays[r],
                        &mut best[r],
                        &mut t_best[r],
                    );
                    t_best_up[r] = t_best[r].f32_up;
                }
            }
            for &pending in &met[..n] {
                stack[sp] = pending;
                sp += 1;
            }
        }
        hits.copy_from_slice(&best[..hits.len()]);
    }
}
