//! The tree traversal reads: the binary SAH tree collapsed into nodes of eight children whose
//! boxes are stored together in `f32`, rounded outward (Wald et al. 2008, "Getting Rid of
//! Packets": multi-branching BVHs; Embree's BVH8). One node, four cache lines, gives a ray eight
//! boxes to test at once — in one AVX2 register, or two SSE ones — so a descent takes a third
//! of the dependent memory loads of the binary tree.
//!
//! The slab test runs in `f32` and is *conservative*: it never rejects a box the exact ray
//! segment meets. Each child's entry distance is padded by a per-ray bound on every rounding
//! the `f32` arithmetic makes (the origin's rounding to `f32`, the subtraction, the product with
//! the rounded reciprocal, the padding's own subtraction), so the hits the exact leaf tests find
//! are those the binary tree in `f64` found. A direction exactly along an axis's slabs tests the
//! origin between their faces; the slabs of an axis along which it is nonzero but tiny (or
//! huge) reject nothing. The test is plain `f32` arithmetic without fused multiply–add, so it
//! gives the same bits on every processor and the visiting order, which decides between equally
//! near hits, is the same everywhere.

use super::{Node, NodeRef, Tree};
use alhazen_math::Ray;

/// Children per node.
pub(super) const WIDTH: usize = 8;
/// A child slot holding nothing.
const EMPTY: u32 = u32::MAX;
/// The unit roundoff of `f32`.
const ROUNDOFF: f64 = 1.0 / (1u64 << 24) as f64;
/// Reciprocal directions beyond this (or below its inverse) make an axis not used to reject:
/// `f32` keeps their relative error bounded without overflow or denormals.
const STEEP: f64 = 1e18;

/// [`WIDTH`] children's boxes, axis by axis, and what each child is.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(super) struct Wide {
    min: [[f32; WIDTH]; 3],
    max: [[f32; WIDTH]; 3],
    /// Leaf child: its first label; interior child: its node's index.
    offset: [u32; WIDTH],
    /// Leaf child: how many labels (at least one); interior child: 0; empty slot: [`EMPTY`].
    count: [u32; WIDTH],
}

impl Wide {
    /// Row `r` of the six rows of planes: `min` along axis `r`, or `max` along axis `r − 3`.
    #[cfg_attr(target_arch = "x86_64", allow(dead_code))]
    fn row(&self, r: usize) -> &[f32; WIDTH] {
        if r < 3 { &self.min[r] } else { &self.max[r - 3] }
    }
}

/// A child to visit: a leaf's labels `offset..offset + count` or, for `count == 0`, node
/// `offset`; `near` is a lower bound of where the ray enters its box.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Entry {
    pub offset: u32,
    pub count: u32,
    pub near: f32,
}

impl Entry {
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    pub fn labels(&self) -> std::ops::Range<usize> {
        self.offset as usize..(self.offset + self.count) as usize
    }
}

/// The largest `f32` at or below `x`.
pub(super) fn down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x { f.next_down() } else { f }
}

/// The smallest `f32` at or above `x`.
pub(super) fn up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x { f.next_up() } else { f }
}

/// The children of `hits` (bit `k` for child `k`) nearest entry first, ties in slot order, as
/// keys for [`slot_of`], and how many. An entry bound is never negative nor NaN (the slab test
/// starts it at +0 and keeps the larger), so its bits order as its value: a key is those bits
/// above the slot, and one integer comparison orders both.
#[inline(always)]
pub(super) fn nearest_first(hits: u32, near: &[f32; WIDTH]) -> ([u64; WIDTH], usize) {
    let mut met = [0u64; WIDTH];
    let (mut n, mut left) = (0, hits);
    while left != 0 {
        let k = left.trailing_zeros() as usize;
        left &= left - 1;
        let key = (near[k].to_bits() as u64) << 32 | k as u64;
        let mut i = n;
        while i > 0 && met[i - 1] > key {
            met[i] = met[i - 1];
            i -= 1;
        }
        met[i] = key;
        n += 1;
    }
    (met, n)
}

/// The child slot of a key of [`nearest_first`].
#[inline(always)]
pub(super) fn slot_of(key: u64) -> usize {
    (key as u32 as usize) % WIDTH
}

/// The nodes of a binary tree as wide nodes, depth first, and the entry of its root: a
/// leaf when the whole tree is one.
pub(super) fn collapse(tree: &Tree) -> (Vec<Wide>, Option<Entry>) {
    if tree.len() == 0 {
        return (vec![], None);
    }
    let root = tree.node(0);
    if root.count > 0 {
        return (vec![], Some(Entry { offset: root.offset, count: root.count, near: 0.0 }));
    }
    let mut wide = Vec::with_capacity(tree.len() / 2);
    let first = wide_node((tree, 0), &mut wide);
    (wide, Some(Entry { offset: first, count: 0, near: 0.0 }))
}

/// Adds the wide node of binary interior node `at` and those below it; returns its index.
/// Its children are `at`'s two, the interior one of largest area replaced by its own two until
/// there are [`WIDTH`] or only leaves.
fn wide_node<'a>((tree, at): NodeRef<'a>, out: &mut Vec<Wide>) -> u32 {
    fn node<'a>((t, i): NodeRef<'a>) -> &'a Node {
        t.node(i)
    }
    let [first, second] = tree.children(at);
    let (mut kids, mut len) = ([first; WIDTH], 2);
    kids[1] = second;
    while len < WIDTH {
        let open = (0..len)
            .filter(|&k| node(kids[k]).count == 0)
            .max_by(|&a, &b| node(kids[a]).bounds().surface_area().total_cmp(&node(kids[b]).bounds().surface_area()));
        let Some(k) = open else { break };
        let (t, n) = kids[k];
        // Its two children take its place, the later ones moving up one slot.
        kids.copy_within(k + 1..len, k + 2);
        [kids[k], kids[k + 1]] = t.children(n);
        len += 1;
    }
    let kids = &kids[..len];
    let me = out.len();
    out.push(Wide {
        min: [[f32::MAX; WIDTH]; 3],
        max: [[-f32::MAX; WIDTH]; 3],
        offset: [0; WIDTH],
        count: [EMPTY; WIDTH],
    });
    for (slot, &kid) in kids.iter().enumerate() {
        let n = node(kid);
        let (offset, count) = if n.count > 0 { (n.offset, n.count) } else { (wide_node(kid, out), 0) };
        let w = &mut out[me];
        // The node's box is already in `f32`.
        for axis in 0..3 {
            w.min[axis][slot] = n.min[axis];
            w.max[axis][slot] = n.max[axis];
        }
        (w.offset[slot], w.count[slot]) = (offset, count);
    }
    me as u32
}

/// Rewrites every leaf's labels with `relabel`.
pub(super) fn relabel(wide: &mut [Wide], root: &mut Option<Entry>, mut relabel: impl FnMut(Entry) -> (u32, u32)) {
    for w in wide.iter_mut() {
        for slot in 0..WIDTH {
            if w.count[slot] != EMPTY && w.count[slot] > 0 {
                let (offset, count) = relabel(Entry { offset: w.offset[slot], count: w.count[slot], near: 0.0 });
                assert!(count > 0, "a leaf keeps at least one label");
                (w.offset[slot], w.count[slot]) = (offset, count);
            }
        }
    }
    if let Some(e) = root.as_mut().filter(|e| e.is_leaf()) {
        (e.offset, e.count) = relabel(*e);
    }
}

/// A ray prepared for the `f32` slab test: per axis its origin and reciprocal direction in
/// `f32`, the padding that bounds their rounding, which face of a box it meets first, and
/// whether it runs exactly parallel to the axis's slabs.
pub(super) struct Slab {
    origin: [f32; 3],
    inv: [f32; 3],
    pad: [f32; 3],
    /// Per axis, the row of a node's six rows of planes (`min` then `max`, axis by axis) the
    /// ray enters by, and the one it leaves by: chosen once per ray, not per node.
    entry_row: [usize; 3],
    exit_row: [usize; 3],
    parallel: [bool; 3],
    /// Whether some axis is `parallel`: nodes test the origin between slabs only then.
    any_parallel: bool,
}

impl Slab {
    /// The ray, for boxes within `reach` of the origin along each axis (the largest magnitude
    /// of any box coordinate).
    #[inline]
    pub fn new(ray: &Ray, reach: [f64; 3]) -> Self {
        // Axis by axis in four lanes (the fourth a dummy), each lane the same arithmetic as
        // the others: a few vector operations rather than three rounds of scalar ones.
        let (o, d) = ([ray.origin.x, ray.origin.y, ray.origin.z, 0.0], [ray.dir.x, ray.dir.y, ray.dir.z, 1.0]);
        let reach = [reach[0], reach[1], reach[2], 0.0];
        let inv: [f64; 4] = std::array::from_fn(|i| 1.0 / d[i]);
        let o32: [f32; 4] = o.map(|x| x as f32);
        let err: [f64; 4] = std::array::from_fn(|i| {
            // |fl(b − o32)·fl(inv) − (b − o)·inv| over boxes within reach, plus the padding's
            // own rounding, is at most (reach + |o32|)·|inv|·(4u + …) + |o − o32|·|inv|·(1 + 3u);
            // the 1 % margins also cover rounding the bound itself to `f32`.
            let (o32, a) = (o32[i] as f64, inv[i].abs());
            ((reach[i] + o32.abs()) * (6.0 * ROUNDOFF) + (o[i] - o32).abs() * 1.01) * a * 1.01 + 1e-30
        });
        // Where the reciprocal is huge or tiny the slabs reject nothing: entry −∞, exit +∞.
        let usable: [bool; 4] = std::array::from_fn(|i| inv[i].abs() < STEEP && inv[i].abs() > 1.0 / STEEP);
        let inv32: [f32; 4] = std::array::from_fn(|i| if usable[i] { inv[i] as f32 } else { 0.0 });
        let pad: [f32; 4] = std::array::from_fn(|i| if usable[i] { err[i] as f32 } else { f32::INFINITY });
        let back: [usize; 3] = std::array::from_fn(|axis| 3 * usize::from(inv[axis] < 0.0));
        // A ray parallel to the slabs meets a box only if its origin lies between them, which
        // rounding to `f32` keeps (rounding is monotonic).
        let parallel = [d[0] == 0.0, d[1] == 0.0, d[2] == 0.0];
        Slab {
            origin: [o32[0], o32[1], o32[2]],
            inv: [inv32[0], inv32[1], inv32[2]],
            pad: [pad[0], pad[1], pad[2]],
            entry_row: std::array::from_fn(|axis| axis + back[axis]),
            exit_row: std::array::from_fn(|axis| axis + 3 - back[axis]),
            parallel,
            any_parallel: parallel.contains(&true),
        }
    }

    /// [`Self::new`] with `AVX2`: its arithmetic in one register of four `f64` lanes (the same
    /// operations in the same order, so the same bits), where the scalar code spends a sixth
    /// of a small mesh's ray test on it.
    ///
    /// # Safety
    /// `AVX2` only on a processor with AVX2 (fast only where the caller is compiled for it).
    #[inline(always)]
    #[allow(unsafe_code)]
    pub unsafe fn of<const AVX2: bool>(ray: &Ray, reach: [f64; 3]) -> Self {
        #[cfg(target_arch = "x86_64")]
        if AVX2 {
            // SAFETY: the caller's contract.
            return unsafe { Self::new_avx2(ray, reach) };
        }
        Self::new(ray, reach)
    }

    /// [`Self::new`] in AVX2 registers.
    ///
    /// # Safety
    /// Only on a processor with AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn new_avx2(ray: &Ray, reach: [f64; 3]) -> Self {
        use std::arch::x86_64::*;
        // SAFETY: the caller's contract; the stores write four lanes into four-lane arrays.
        unsafe {
            let o = _mm256_setr_pd(ray.origin.x, ray.origin.y, ray.origin.z, 0.0);
            let d = _mm256_setr_pd(ray.dir.x, ray.dir.y, ray.dir.z, 1.0);
            let reach = _mm256_setr_pd(reach[0], reach[1], reach[2], 0.0);
            let zero = _mm256_setzero_pd();
            let abs = |x| _mm256_andnot_pd(_mm256_set1_pd(-0.0), x);
            let inv = _mm256_div_pd(_mm256_set1_pd(1.0), d);
            let o32 = _mm256_cvtpd_ps(o);
            let o32d = _mm256_cvtps_pd(o32);
            let a = abs(inv);
            let bound = _mm256_add_pd(
                _mm256_mul_pd(_mm256_add_pd(reach, abs(o32d)), _mm256_set1_pd(6.0 * ROUNDOFF)),
                _mm256_mul_pd(abs(_mm256_sub_pd(o, o32d)), _mm256_set1_pd(1.01)),
            );
            let err =
                _mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(bound, a), _mm256_set1_pd(1.01)), _mm256_set1_pd(1e-30));
            let usable = _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_LT_OQ>(a, _mm256_set1_pd(STEEP)),
                _mm256_cmp_pd::<_CMP_GT_OQ>(a, _mm256_set1_pd(1.0 / STEEP)),
            );
            let (mut origin, mut inv32, mut pad) = ([0.0f32; 4], [0.0f32; 4], [0.0f32; 4]);
            _mm_storeu_ps(origin.as_mut_ptr(), o32);
            _mm_storeu_ps(inv32.as_mut_ptr(), _mm256_cvtpd_ps(_mm256_and_pd(usable, inv)));
            let pad64 = _mm256_blendv_pd(_mm256_set1_pd(f64::INFINITY), err, usable);
            _mm_storeu_ps(pad.as_mut_ptr(), _mm256_cvtpd_ps(pad64));
            let back = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(inv, zero)) as usize;
            let flat = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_EQ_OQ>(d, zero)) as usize;
            let parallel = [flat & 1 != 0, flat & 2 != 0, flat & 4 != 0];
            let rows = |axis: usize| 3 * (back >> axis & 1);
            Slab {
                origin: [origin[0], origin[1], origin[2]],
                inv: [inv32[0], inv32[1], inv32[2]],
                pad: [pad[0], pad[1], pad[2]],
                entry_row: std::array::from_fn(|axis| axis + rows(axis)),
                exit_row: std::array::from_fn(|axis| axis + 3 - rows(axis)),
                parallel,
                any_parallel: flat & 7 != 0,
            }
        }
    }

    /// Which of `w`'s children the ray may meet within `[0, t_max]` (bit `k` for child `k`)
    /// and lower bounds of where it enters each: with `AVX2`, all eight children in one AVX
    /// register; otherwise in two halves of four in SSE registers (which every x86-64
    /// processor has), or one by one on other processors. Every way gives the same bits.
    ///
    /// # Safety
    /// `AVX2` only on a processor with AVX2 (fast only where the caller is compiled for it).
    #[inline(always)]
    #[allow(unsafe_code)]
    pub unsafe fn test<const AVX2: bool>(&self, w: &Wide, t_max: f32) -> (u32, [f32; WIDTH]) {
        #[cfg(target_arch = "x86_64")]
        {
            if AVX2 {
                // SAFETY: the caller's contract.
                unsafe { self.test_avx2(w, t_max) }
            } else {
                self.test_sse(w, t_max)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self.test_portable(w, t_max)
        }
    }

    /// [`Self::test`] one child at a time: the same arithmetic in the same order.
    #[cfg_attr(target_arch = "x86_64", allow(dead_code))]
    fn test_portable(&self, w: &Wide, t_max: f32) -> (u32, [f32; WIDTH]) {
        let mut near = [0.0f32; WIDTH];
        let mut far = [t_max; WIDTH];
        let mut beside = [false; WIDTH];
        for axis in 0..3 {
            let (entry, exit) = (w.row(self.entry_row[axis]), w.row(self.exit_row[axis]));
            let (o, inv, pad) = (self.origin[axis], self.inv[axis], self.pad[axis]);
            if self.parallel[axis] {
                for k in 0..WIDTH {
                    beside[k] |= !(w.min[axis][k] <= o && o <= w.max[axis][k]);
                }
            }
            for k in 0..WIDTH {
                // `a > b ? a : b` keeps the accumulator when the new value is NaN (0·∞ on an
                // axis not used to reject), as the processors' max and min instructions do.
                let t0 = (entry[k] - o) * inv - pad;
                let t1 = (exit[k] - o) * inv + pad;
                near[k] = if t0 > near[k] { t0 } else { near[k] };
                far[k] = if t1 < far[k] { t1 } else { far[k] };
            }
        }
        let mut hits = 0;
        for k in 0..WIDTH {
            hits |= u32::from(near[k] <= far[k] && w.count[k] != EMPTY && !beside[k]) << k;
        }
        (hits, near)
    }

    /// [`Self::test`] with SSE, which every x86-64 processor has: four children at a time.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(unsafe_code)]
    fn test_sse(&self, w: &Wide, t_max: f32) -> (u32, [f32; WIDTH]) {
        use std::arch::x86_64::*;
        const HALF: usize = WIDTH / 2;
        // SAFETY: SSE and SSE2 are part of x86-64; each load reads four of a row's eight `f32`s
        // (or `u32`s), 16-byte aligned in a 64-byte aligned node; `Wide` is `repr(C)`, so its
        // `min` and `max` are six consecutive rows, and the rows chosen are below six.
        const { assert!(std::mem::offset_of!(Wide, max) == std::mem::size_of::<[[f32; WIDTH]; 3]>()) };
        unsafe {
            let rows = (&raw const w.min).cast::<[f32; WIDTH]>();
            let (mut hits, mut out) = (0, [0.0f32; WIDTH]);
            for half in 0..2 {
                let row = |r: usize| _mm_load_ps(rows.add(r).cast::<f32>().add(half * HALF));
                let mut near = _mm_setzero_ps();
                let mut far = _mm_set1_ps(t_max);
                let count = _mm_load_si128(w.count.as_ptr().add(half * HALF).cast());
                let mut beside = _mm_castsi128_ps(_mm_cmpeq_epi32(count, _mm_set1_epi32(-1)));
                if self.any_parallel {
                    for axis in (0..3).filter(|&a| self.parallel[a]) {
                        let o = _mm_set1_ps(self.origin[axis]);
                        let inside = _mm_and_ps(_mm_cmple_ps(row(axis), o), _mm_cmple_ps(o, row(axis + 3)));
                        beside = _mm_or_ps(beside, _mm_andnot_ps(inside, _mm_castsi128_ps(_mm_set1_epi32(-1))));
                    }
                }
                for axis in 0..3 {
                    let (o, inv, pad) =
                        (_mm_set1_ps(self.origin[axis]), _mm_set1_ps(self.inv[axis]), _mm_set1_ps(self.pad[axis]));
                    let t0 = _mm_sub_ps(_mm_mul_ps(_mm_sub_ps(row(self.entry_row[axis]), o), inv), pad);
                    let t1 = _mm_add_ps(_mm_mul_ps(_mm_sub_ps(row(self.exit_row[axis]), o), inv), pad);
                    // MAXPS/MINPS return their second operand when either is NaN: the accumulator.
                    near = _mm_max_ps(t0, near);
                    far = _mm_min_ps(t1, far);
                }
                // Empty slots count as beside the ray.
                hits |= (_mm_movemask_ps(_mm_andnot_ps(beside, _mm_cmple_ps(near, far))) as u32) << (half * HALF);
                _mm_storeu_ps(out.as_mut_ptr().add(half * HALF), near);
            }
            (hits, out)
        }
    }

    /// [`Self::test`] with AVX2: eight children at once, the same operations as [`Self::test_sse`]
    /// on twice the lanes.
    ///
    /// # Safety
    /// Only on a processor with AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn test_avx2(&self, w: &Wide, t_max: f32) -> (u32, [f32; WIDTH]) {
        use std::arch::x86_64::*;
        // SAFETY: the caller's contract gives AVX2; the loads read whole 32-byte aligned rows
        // of a 64-byte aligned node (`Wide` is `repr(C)`: `min` and `max` are six consecutive
        // rows), and the rows chosen are below six.
        unsafe {
            let rows = (&raw const w.min).cast::<[f32; WIDTH]>();
            let row = |r: usize| _mm256_load_ps(rows.add(r).cast());
            let (le, all) = (|a, b| _mm256_cmp_ps::<_CMP_LE_OQ>(a, b), _mm256_set1_epi32(-1));
            let mut near = _mm256_setzero_ps();
            let mut far = _mm256_set1_ps(t_max);
            let count = _mm256_load_si256(w.count.as_ptr().cast());
            let mut beside = _mm256_castsi256_ps(_mm256_cmpeq_epi32(count, all));
            if self.any_parallel {
                for axis in (0..3).filter(|&a| self.parallel[a]) {
                    let o = _mm256_set1_ps(self.origin[axis]);
                    let inside = _mm256_and_ps(le(row(axis), o), le(o, row(axis + 3)));
                    beside = _mm256_or_ps(beside, _mm256_andnot_ps(inside, _mm256_castsi256_ps(all)));
                }
            }
            for axis in 0..3 {
                let (o, inv, pad) =
                    (_mm256_set1_ps(self.origin[axis]), _mm256_set1_ps(self.inv[axis]), _mm256_set1_ps(self.pad[axis]));
                let t0 = _mm256_sub_ps(_mm256_mul_ps(_mm256_sub_ps(row(self.entry_row[axis]), o), inv), pad);
                let t1 = _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(row(self.exit_row[axis]), o), inv), pad);
                // VMAXPS/VMINPS return their second operand when either is NaN: the accumulator.
                near = _mm256_max_ps(t0, near);
                far = _mm256_min_ps(t1, far);
            }
            let hits = _mm256_movemask_ps(_mm256_andnot_ps(beside, le(near, far))) as u32;
            let mut out = [0.0f32; WIDTH];
            _mm256_storeu_ps(out.as_mut_ptr(), near);
            (hits, out)
        }
    }

    /// Asks the processor to start loading node `w` (its two cache lines).
    #[inline(always)]
    pub fn prefetch(w: &Wide) {
        const { assert!(std::mem::size_of::<Wide>() == 64 * WIDTH / 2) };
        crate::prefetch::prefetch_all(w);
    }

    /// `w`'s child `k`.
    #[inline]
    pub fn child(w: &Wide, k: usize, near: f32) -> Entry {
        Entry { offset: w.offset[k], count: w.count[k], near }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alhazen_math::{Bounds3, Vec3};

    fn one_box(b: Bounds3) -> Wide {
        let mut w = Wide {
            min: [[f32::MAX; WIDTH]; 3],
            max: [[-f32::MAX; WIDTH]; 3],
            offset: [0; WIDTH],
            count: [EMPTY; WIDTH],
        };
        for axis in 0..3 {
            (w.min[axis][0], w.max[axis][0]) = (down(b.min[axis]), up(b.max[axis]));
        }
        w.count[0] = 1;
        w
    }

    proptest::proptest! {
        /// A rounded box holds the exact one, as tightly as `f32` allows.
        #[test]
        fn rounded_boxes_hold_the_exact_ones(x in -1e30..1e30f64, scale in -30i32..30) {
            let x = x * 10f64.powi(scale);
            let (lo, hi) = (down(x), up(x));
            proptest::prop_assert!((lo as f64) <= x && x <= hi as f64);
            proptest::prop_assert!(lo == hi || lo.next_up() == hi, "{lo} {hi}");
        }

        /// Whatever the exact ray segment meets, the `f32` test keeps, and its entry bound is
        /// below the exact entry: rays grazing faces, starting on them, along the axes, far away.
        #[test]
        fn the_f32_test_never_rejects_a_box_the_ray_meets(
            lo in proptest::array::uniform3(-1e3..1e3f64),
            size in proptest::array::uniform3(0.0..1e2f64),
            scale in -12i32..12,
            u in proptest::array::uniform3(0.0..1.0f64),
            from in proptest::array::uniform3(-1e4..1e4f64),
            zero in 0usize..5,
        ) {
            let s = 10f64.powi(scale);
            let lo = Vec3::from_array(lo) * s;
            let b = Bounds3 { min: lo, max: lo + Vec3::from_array(size) * s };
            // A point of the box (on its faces for u at 0 or 1) and a ray through it.
            let target = b.min + (b.max - b.min) * Vec3::from_array(u);
            let origin = Vec3::from_array(from) * s;
            let mut dir = target - origin;
            if zero < 3 {
                dir[zero] = 0.0;
            }
            proptest::prop_assume!(dir.length() > 0.0);
            let ray = Ray::new(origin, dir);
            let reach: [f64; 3] = std::array::from_fn(|a| (b.min[a].abs()).max(b.max[a].abs()));
            let slab = Slab::new(&ray, reach.map(|r| up(r) as f64));
            let w = one_box(b);
            let exact = b.hit_interval(&ray, 1.0 / ray.dir, f64::INFINITY);
            let (hits, near) = portable_or_sse(&slab, &w, f32::INFINITY);
            if let Some((t_near, _)) = exact {
                proptest::prop_assert!(hits & 1 == 1, "rejected {b:?} for {ray:?}");
                proptest::prop_assert!(near[0] as f64 <= t_near);
            }
            // The exact point of entry is kept with the segment ending there.
            if let Some((t_near, _)) = exact {
                let (hits, _) = portable_or_sse(&slab, &w, up(t_near));
                proptest::prop_assert!(hits & 1 == 1);
            }
            proptest::prop_assert!(hits & !1 == 0, "empty slots are never met");
        }
    }

    /// [`Slab::test`] without AVX2.
    #[allow(unsafe_code)]
    fn portable_or_sse(slab: &Slab, w: &Wide, t_max: f32) -> (u32, [f32; WIDTH]) {
        // SAFETY: without AVX2.
        unsafe { slab.test::<false>(w, t_max) }
    }

    proptest::proptest! {
        /// The SSE and AVX2 tests give the portable test's bits, children in every slot of
        /// both halves, empty slots among them, rays along the axes and not.
        #[cfg(target_arch = "x86_64")]
        #[test]
        #[allow(unsafe_code)]
        fn sse_avx2_and_portable_tests_agree(
            boxes in proptest::collection::vec((proptest::array::uniform3(-4.0..4.0f32), proptest::array::uniform3(0.0..3.0f32), 0u32..3), WIDTH),
            origin in proptest::array::uniform3(-6.0..6.0f64),
            dir in proptest::array::uniform3(-1.0..1.0f64),
            flat_axis in 0usize..4,
            t_max in proptest::sample::select(vec![f32::INFINITY, 5.0, 1.0, 0.0]),
        ) {
            let mut w = one_box(Bounds3::EMPTY);
            for (k, (lo, size, kind)) in boxes.into_iter().enumerate() {
                for axis in 0..3 {
                    (w.min[axis][k], w.max[axis][k]) = (lo[axis], lo[axis] + size[axis]);
                }
                // Leaves, interior nodes and empty slots.
                w.count[k] = [1, 0, EMPTY][kind as usize];
            }
            let mut dir = Vec3::from_array(dir);
            if flat_axis < 3 {
                dir[flat_axis] = 0.0;
            }
            proptest::prop_assume!(dir.length() > 1e-3);
            let slab = Slab::new(&Ray::new(Vec3::from_array(origin), dir), [10.0; 3]);
            let portable = slab.test_portable(&w, t_max);
            let bits = |(hits, near): (u32, [f32; WIDTH])| (hits, near.map(f32::to_bits));
            proptest::prop_assert_eq!(bits(slab.test_sse(&w, t_max)), bits(portable));
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the processor has AVX2.
                let avx2 = unsafe { slab.test_avx2(&w, t_max) };
                proptest::prop_assert_eq!(bits(avx2), bits(portable));
            }
        }
    }

    proptest::proptest! {
        /// The AVX2 preparation of a ray gives the scalar one's bits: rays along the axes, far
        /// away, with tiny and huge components.
        #[cfg(target_arch = "x86_64")]
        #[test]
        #[allow(unsafe_code)]
        fn avx2_and_scalar_slabs_agree(
            origin in proptest::array::uniform3(-1e6..1e6f64),
            dir in proptest::array::uniform3(-1.0..1.0f64),
            scale in proptest::array::uniform3(-25i32..25),
            zero in 0usize..5,
            reach in proptest::array::uniform3(0.0..1e6f64),
        ) {
            let mut d = Vec3::from_array(dir) * Vec3::from_array(scale.map(|e| 10f64.powi(e)));
            if zero < 3 {
                d[zero] = 0.0;
            }
            let ray = Ray::new(Vec3::from_array(origin), d);
            proptest::prop_assume!(std::arch::is_x86_feature_detected!("avx2"));
            let scalar = Slab::new(&ray, reach);
            // SAFETY: the processor has AVX2.
            let avx2 = unsafe { Slab::of::<true>(&ray, reach) };
            let bits = |s: &Slab| (s.origin.map(f32::to_bits), s.inv.map(f32::to_bits), s.pad.map(f32::to_bits), s.entry_row, s.exit_row, s.parallel, s.any_parallel);
            proptest::prop_assert_eq!(bits(&avx2), bits(&scalar));
        }
    }

    proptest::proptest! {
        /// The children met come nearest first, ties in slot order: a stable sort of the
        /// slots by their entry bounds (which the slab test keeps at +0 or above).
        #[test]
        fn children_met_come_nearest_first(hits in 0u32..256, near in proptest::array::uniform8(proptest::sample::select(vec![0.0f32, 0.5, 1.0, 1e30, f32::INFINITY]))) {
            let (met, n) = nearest_first(hits, &near);
            let mut expected: Vec<usize> = (0..WIDTH).filter(|k| hits >> k & 1 == 1).collect();
            expected.sort_by(|&a, &b| near[a].total_cmp(&near[b]));
            proptest::prop_assert_eq!(met[..n].iter().map(|&key| slot_of(key)).collect::<Vec<_>>(), expected);
        }
    }

    #[test]
    fn boxes_behind_beside_and_beyond_are_rejected() {
        let b = Bounds3 { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) };
        let w = one_box(b);
        let reach = [1.0; 3];
        let test = |o: Vec3, d: Vec3, t_max: f32| portable_or_sse(&Slab::new(&Ray::new(o, d), reach), &w, t_max).0 & 1;
        assert_eq!(test(Vec3::new(-5.0, 0.0, 0.0), Vec3::X, f32::INFINITY), 1);
        assert_eq!(test(Vec3::new(5.0, 0.0, 0.0), Vec3::X, f32::INFINITY), 0, "behind");
        assert_eq!(test(Vec3::new(-5.0, 2.0, 0.0), Vec3::X, f32::INFINITY), 0, "beside");
        assert_eq!(test(Vec3::new(-5.0, 0.0, 0.0), Vec3::X, 3.9), 0, "beyond the segment");
        assert_eq!(test(Vec3::new(-5.0, 0.0, 0.0), Vec3::new(1.0, 0.5, 0.0), f32::INFINITY), 0, "passes above");
    }
}
