//! A k-d tree over points (course, §"Spatial data structures": the k-d tree splits space by
//! alternating axis-aligned planes; here the axis of largest extent, at the median, so the
//! tree is balanced and stored implicitly: the node of a range is its middle element).
//! Queries find the `k` nearest points within a radius, as photon density estimation needs.

use alhazen_math::Vec3;
use std::collections::BinaryHeap;

/// A balanced k-d tree of items with positions, stored in one array.
#[derive(Clone, Debug, Default)]
pub struct KdTree<T> {
    items: Vec<T>,
    /// Splitting axis of the node at each index (the middle of its range).
    axes: Vec<u8>,
}

/// What the tree holds: anything with a position.
pub trait Located {
    /// The position.
    fn position(&self) -> Vec3;
}

impl Located for Vec3 {
    fn position(&self) -> Vec3 {
        *self
    }
}

/// A found item: its index in [`KdTree::items`] and squared distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbour {
    /// Index into [`KdTree::items`].
    pub index: u32,
    /// Squared distance from the query point.
    pub dist2: f64,
}

impl<T: Located> KdTree<T> {
    /// The tree of `items` (reordered). Deterministic: ties are broken by the items' order.
    pub fn build(items: Vec<T>) -> Self {
        let mut keyed: Vec<(Vec3, u32)> = items.iter().enumerate().map(|(i, t)| (t.position(), i as u32)).collect();
        let mut axes = vec![0u8; items.len()];
        split(&mut keyed, &mut axes);
        let mut slots: Vec<Option<T>> = items.into_iter().map(Some).collect();
        let items = keyed.iter().map(|&(_, i)| slots[i as usize].take().expect("each item once")).collect();
        Self { items, axes }
    }

    /// The items in tree order.
    pub fn items(&self) -> &[T] {
        &self.items
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The (at most) `k` nearest items to `p` closer than `radius` that `keep` accepts, written
    /// to `out` in no particular order.
    pub fn nearest(&self, p: Vec3, k: usize, radius: f64, keep: impl Fn(&T) -> bool, out: &mut Vec<Neighbour>) {
        out.clear();
        if k == 0 || self.items.is_empty() {
            return;
        }
        HEAP.with(|cell| {
            // One heap per thread, reused: a query at every diffuse vertex allocates nothing.
            let mut heap = cell.borrow_mut();
            heap.clear();
            let mut search = Search { tree: self, p, k, r2: radius * radius, heap: &mut heap, keep: &keep };
            search.visit(0, self.items.len());
            out.extend(heap.drain().map(|(bits, index)| Neighbour { index, dist2: f64::from_bits(bits) }));
        });
    }
}

thread_local! {
    static HEAP: std::cell::RefCell<BinaryHeap<(u64, u32)>> = const { std::cell::RefCell::new(BinaryHeap::new()) };
}

/// Sorts `keyed` into tree order: the median (by the axis of largest extent) in the middle,
/// then each half the same way.
fn split(keyed: &mut [(Vec3, u32)], axes: &mut [u8]) {
    if keyed.len() <= 1 {
        return;
    }
    let (lo, hi) =
        keyed.iter().fold((Vec3::splat(f64::MAX), Vec3::splat(f64::MIN)), |(lo, hi), (p, _)| (lo.min(*p), hi.max(*p)));
    let extent = hi - lo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = keyed.len() / 2;
    keyed.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]).then(a.1.cmp(&b.1)));
    axes[mid] = axis as u8;
    let (left, right) = keyed.split_at_mut(mid);
    let (axes_left, axes_right) = axes.split_at_mut(mid);
    split(left, axes_left);
    split(&mut right[1..], &mut axes_right[1..]);
}

/// One query's state: the heap holds `(dist² bits, index)`, largest on top (non-negative
/// floats order as their bits).
struct Search<'a, T, F> {
    tree: &'a KdTree<T>,
    p: Vec3,
    k: usize,
    r2: f64,
    heap: &'a mut BinaryHeap<(u64, u32)>,
    keep: &'a F,
}

impl<T: Located, F: Fn(&T) -> bool> Search<'_, T, F> {
    fn visit(&mut self, lo: usize, hi: usize) {
        if lo >= hi {
            return;
        }
        let mid = lo + (hi - lo) / 2;
        let axis = self.tree.axes[mid] as usize;
        let item = &self.tree.items[mid];
        let d = self.p[axis] - item.position()[axis];
        let (near, far) = if d < 0.0 { ((lo, mid), (mid + 1, hi)) } else { ((mid + 1, hi), (lo, mid)) };
        self.visit(near.0, near.1);
        self.consider(mid);
        if d * d < self.r2 {
            self.visit(far.0, far.1);
        }
    }

    fn consider(&mut self, i: usize) {
        let item = &self.tree.items[i];
        let dist2 = (item.position() - self.p).length_squared();
        if dist2 >= self.r2 || !(self.keep)(item) {
            return;
        }
        self.heap.push((dist2.to_bits(), i as u32));
        if self.heap.len() > self.k {
            self.heap.pop();
        }
        if self.heap.len() == self.k {
            self.r2 = f64::from_bits(self.heap.peek().expect("k ≥ 1 items").0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn the_k_nearest_are_those_of_a_brute_force_search(
            pts in prop::collection::vec((-5.0..5.0f64, -5.0..5.0f64, -5.0..5.0f64), 0..300),
            q in (-6.0..6.0f64, -6.0..6.0f64, -6.0..6.0f64),
            k in 1usize..20,
            radius in 0.1..8.0f64,
        ) {
            let pts: Vec<Vec3> = pts.into_iter().map(|(x, y, z)| Vec3::new(x, y, z)).collect();
            let q = Vec3::new(q.0, q.1, q.2);
            let tree = KdTree::build(pts.clone());
            let mut found = vec![];
            tree.nearest(q, k, radius, |_| true, &mut found);
            let mut ours: Vec<f64> = found.iter().map(|n| n.dist2).collect();
            ours.sort_by(f64::total_cmp);
            let mut brute: Vec<f64> = pts.iter().map(|p| (*p - q).length_squared()).filter(|d| *d < radius * radius).collect();
            brute.sort_by(f64::total_cmp);
            brute.truncate(k);
            prop_assert_eq!(ours, brute);
            for n in &found {
                prop_assert_eq!((tree.items()[n.index as usize] - q).length_squared(), n.dist2);
            }
        }
    }

    #[test]
    fn a_filter_skips_items_without_ending_the_search() {
        let pts: Vec<Vec3> = (0..100).map(|i| Vec3::new(i as f64, 0.0, 0.0)).collect();
        let tree = KdTree::build(pts);
        let mut found = vec![];
        tree.nearest(Vec3::ZERO, 3, 1e9, |p| p.x as i64 % 2 == 1, &mut found);
        let mut xs: Vec<f64> = found.iter().map(|n| tree.items()[n.index as usize].x).collect();
        xs.sort_by(f64::total_cmp);
        assert_eq!(xs, vec![1.0, 3.0, 5.0]);
    }
}
