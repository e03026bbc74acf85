//! A bounding volume hierarchy built with the surface area heuristic (binned SAH, 12 bins) or,
//! for speed of building, in Morton order (the course's Morton codes: the centroids' coordinates
//! interleaved bit by bit, sorted, and each node split where its first and last codes first
//! differ — a linear BVH), flattened depth-first so that a node's first child follows it. Used twice: over the objects
//! of a scene and over the triangles of each mesh. The world's tree charges one test per
//! started group of eight packed primitives ([`Bvh::build_packed`]: flats and spheres), so a room
//! of walls, boxes and balls becomes one leaf of packets rather than a tree of overlapping boxes.

use alhazen_math::{Bounds3, Ray, Vec3};
use rayon::prelude::*;
use wide::{Entry, Slab, WIDTH, Wide};

mod wide;

const BINS: usize = 12;
/// Deeper subtrees become leaves, so traversal's fixed stack never overflows.
const MAX_DEPTH: usize = 48;
/// Traversal's stack: each wide node on the way down leaves at most `WIDTH − 1` children
/// waiting (the collapsed tree is no deeper than the binary one).
const STACK: usize = (WIDTH - 1) * (MAX_DEPTH + 2);
/// Nodes over at least this many primitives build their two subtrees in parallel (the same
/// tree as one thread builds: only who computes each subtree changes).
const PARALLEL_ITEMS: usize = 1 << 14;

#[derive(Clone, Copy, Debug)]
struct Node {
    /// Its box: a union of [`Item`]s' boxes, so `f32` holds it exactly (36-byte nodes).
    min: [f32; 3],
    max: [f32; 3],
    /// Leaf: its first item's position in [`Bvh::leaf_order`]; interior: where its second
    /// child is — an index into its [`Tree`]'s nodes, or, when `remote`, into its subtrees.
    offset: u32,
    /// Number of primitives in a leaf, 0 for an interior node.
    count: u32,
    /// The second child was built on its own ([`Tree::subtrees`]).
    remote: bool,
}

/// The binary tree while it is built: its nodes depth first, a node's first child after it.
/// The second half of a node split on another thread stays in its own tree, one of
/// `subtrees`: no node is copied (on a VM that backs fresh memory slowly, the copies were a
/// sixth of a million-triangle build).
#[derive(Default)]
struct Tree {
    nodes: Vec<Node>,
    subtrees: Vec<Tree>,
}

/// A node: the tree that holds it and its index there.
type NodeRef<'a> = (&'a Tree, usize);

/// A BVH over primitives given by their bounds; it stores indices, not primitives.
#[derive(Clone, Debug)]
pub struct Bvh {
    /// The nodes for traversal, [`WIDTH`] children each, depth first.
    wide: Vec<Wide>,
    /// Where traversal starts: the first wide node, or the one leaf; `None` when empty.
    start: Option<Entry>,
    /// The exact bounds of everything.
    root: Bounds3,
    /// Per axis, the largest magnitude of a coordinate of any node's `f32` box.
    reach: [f64; 3],
    /// The leaves' labels were rewritten ([`Self::relabel_leaves`]): they no longer index
    /// [`Self::leaf_order`].
    relabeled: bool,
    /// Primitive indices in leaf order.
    order: Vec<u32>,
}

/// What a traversal does at a leaf: `visit(labels, t_max)` returns a closer hit distance, or
/// `Some(0.0)` to stop ([`Bvh::traverse_leaves`]). Any closure of that shape is one; a type of
/// its own can promise to be inlined into the traversal (`#[inline(always)]`), which a closure
/// cannot — and a leaf test in vector registers must be, to be compiled for them.
pub trait LeafVisit {
    /// Visits the leaf of `labels` with the closest hit so far at `t_max`.
    fn visit(&mut self, labels: std::ops::Range<usize>, t_max: f64) -> Option<f64>;
}

impl<F: FnMut(std::ops::Range<usize>, f64) -> Option<f64>> LeafVisit for F {
    #[inline(always)]
    fn visit(&mut self, labels: std::ops::Range<usize>, t_max: f64) -> Option<f64> {
        self(labels, t_max)
    }
}

impl Tree {
    /// An empty tree with room for one over `items` primitives (at most `2·items − 1` nodes;
    /// pages reserved and never written cost no memory).
    fn reserved(items: usize) -> Self {
        Tree { nodes: Vec::with_capacity(2 * items), subtrees: vec![] }
    }

    /// How many nodes it holds, its subtrees' included.
    fn len(&self) -> usize {
        self.nodes.len() + self.subtrees.iter().map(Tree::len).sum::<usize>()
    }

    /// The node `at`.
    fn node(&self, at: usize) -> &Node {
        &self.nodes[at]
    }

    /// The children of interior node `at`.
    fn children(&self, at: usize) -> [NodeRef<'_>; 2] {
        let n = &self.nodes[at];
        let second = if n.remote { (&self.subtrees[n.offset as usize], 0) } else { (self, n.offset as usize) };
        [(self, at + 1), second]
    }

    /// Builds the subtree over `items`, whose [`Summary`] is `node` and whose first item is
    /// the `first`th of all; returns its index.
    fn build(
        &mut self,
        items: &mut [Item],
        first: usize,
        node: Summary,
        depth: usize,
        how: Split,
        parallel_from: usize,
        leaves: Leaves,
    ) -> usize {
        let me = self.nodes.len();
        let (min, max) = ([node.lo[0], node.lo[1], node.lo[2]], [node.hi[0], node.hi[1], node.hi[2]]);
        self.nodes.push(Node { min, max, offset: first as u32, count: items.len() as u32, remote: false });
        let cost = node.tests.cost(leaves.pack);
        // The whole set within `whole` tests stays one leaf if its packets would fit a leaf:
        // its other primitives are each culled by their own box, its packets are not.
        let whole =
            depth == 0 && cost <= leaves.whole as f64 && node.tests.packed.div_ceil(leaves.pack) <= leaves.max_tests;
        let small = items.len() == 1 || cost <= leaves.max_tests as f64 || whole;
        let split = match how {
            _ if small || depth >= MAX_DEPTH => None,
            Split::Sah { traversal } => sah_split(items, &node, traversal, leaves.pack),
            Split::Morton { codes } => Some((morton_split(codes), None)),
        };
        // A leaf as pushed, unless split.
        let Some((mid, halves)) = split else { return me };
        let parallel = items.len() >= parallel_from;
        let (left, right) = items.split_at_mut(mid);
        // The halves' summaries come with the split when it is the bins' (the same unions of
        // the same boxes, in another order: the same bits).
        let [sl, sr] = halves.unwrap_or_else(|| [Summary::of(left), Summary::of(right)]);
        let (hl, hr) = how.split_at(mid);
        let (next, second_first) = (depth + 1, first + mid);
        let second = if parallel {
            // The first half goes on in this tree, where the sequential build puts it; the
            // second is built apart (its nodes reserved whole: no copies as they grow) and
            // kept as a subtree.
            let mut b = Tree::reserved(right.len());
            rayon::join(
                || self.build(left, first, sl, next, hl, parallel_from, leaves),
                || b.build(right, second_first, sr, next, hr, parallel_from, leaves),
            );
            self.subtrees.push(b);
            self.subtrees.len() - 1
        } else {
            self.build(left, first, sl, next, hl, parallel_from, leaves);
            self.build(right, second_first, sr, next, hr, parallel_from, leaves)
        };
        self.nodes[me] = Node { offset: second as u32, count: 0, remote: parallel, ..self.nodes[me] };
        me
    }
}

impl Node {
    fn bounds(&self) -> Bounds3 {
        f32_box(&self.min, &self.max)
    }
}

impl Default for Bvh {
    fn default() -> Self {
        Bvh { wide: vec![], start: None, root: Bounds3::EMPTY, reach: [0.0; 3], relabeled: false, order: vec![] }
    }
}

/// A primitive while building: 32 bytes, its bounds rounded outwards to `f32` (as traversal's
/// nodes hold them: the nodes' boxes are the same) and its centroid computed from them when
/// needed, so a million of them are 32 MB of fresh memory and move through the caches as few
/// lines as possible.
#[derive(Clone, Copy)]
struct Item {
    min: [f32; 3],
    max: [f32; 3],
    index: u32,
    /// Tested several at a time ([`Leaves::pack`]).
    packed: bool,
    /// The bin of its centroid in the last binning of its node (SAH builds only).
    bin: u8,
}

impl Item {
    fn new(index: usize, b: Bounds3, packed: bool) -> Self {
        Item {
            min: std::array::from_fn(|a| wide::down(b.min[a])),
            max: std::array::from_fn(|a| wide::up(b.max[a])),
            index: index as u32,
            packed,
            bin: 0,
        }
    }

    #[inline(always)]
    fn bounds(&self) -> Bounds3 {
        f32_box(&self.min, &self.max)
    }

    /// Its box as [`Lanes4`].
    #[inline(always)]
    fn lanes(&self) -> (Lanes4, Lanes4) {
        let (l, h) = (self.min, self.max);
        ([l[0], l[1], l[2], l[2]], [h[0], h[1], h[2], h[2]])
    }
}

/// The box with corners `min`, `max` (their first three coordinates), in `f64`.
#[inline(always)]
fn f32_box(min: &[f32], max: &[f32]) -> Bounds3 {
    let v = |c: &[f32]| Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64);
    Bounds3 { min: v(min), max: v(max) }
}

/// How a [`Bvh`] chooses its splits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BuildMethod {
    /// The surface area heuristic: the better tree.
    #[default]
    Sah,
    /// Morton order: the faster build.
    Morton,
}

/// How many primitives of each kind a set holds, for the cost of testing it as one leaf.
#[derive(Clone, Copy, Default)]
struct Tests {
    packed: usize,
    single: usize,
}

impl Tests {
    fn add(self, it: &Item) -> Self {
        Self { packed: self.packed + usize::from(it.packed), single: self.single + usize::from(!it.packed) }
    }

    fn merge(self, o: Self) -> Self {
        Self { packed: self.packed + o.packed, single: self.single + o.single }
    }

    /// Tests a ray makes in the leaf, in units of one primitive test.
    fn cost(self, pack: usize) -> f64 {
        (self.packed.div_ceil(pack) + self.single) as f64
    }
}

impl Bvh {
    /// Builds over `bounds[i]` for every primitive `i`.
    pub fn build(bounds: &[Bounds3]) -> Self {
        Self::build_packed(bounds, |_| false)
    }

    /// A mesh's tree (`Leaves::MESH`) by `method`, over `count` primitives whose bounds
    /// `bounds(i)` gives: no vector of them is made (a million-triangle mesh's would be 48 MB
    /// of fresh memory).
    pub fn build_with(
        count: usize,
        bounds: impl Fn(usize) -> Bounds3 + Sync,
        packed: impl Fn(usize) -> bool + Sync,
        method: BuildMethod,
    ) -> Self {
        Self::build_split_from(count, bounds, packed, PARALLEL_ITEMS, method, Leaves::MESH)
    }

    /// [`Self::build`] for primitives some of which (`packed(i)`) are tested eight at a time
    /// in a leaf: the surface area heuristic charges a leaf one test per started group of
    /// them plus one per other primitive (`Leaves::WORLD`), so leaves of such primitives grow
    /// large.
    pub fn build_packed(bounds: &[Bounds3], packed: impl Fn(usize) -> bool + Sync) -> Self {
        Self::build_packed_within(bounds, packed, 0)
    }

    /// [`Self::build_packed`], one leaf when all the primitives together cost at most `whole`
    /// tests and their packets fit a leaf.
    pub fn build_packed_within(bounds: &[Bounds3], packed: impl Fn(usize) -> bool + Sync, whole: usize) -> Self {
        let leaves = Leaves { whole, ..Leaves::WORLD };
        Self::build_split_from(bounds.len(), |i| bounds[i], packed, PARALLEL_ITEMS, BuildMethod::Sah, leaves)
    }

    /// [`Self::build_packed`] building subtrees of at least `parallel_from` primitives in
    /// parallel.
    fn build_split_from(
        count: usize,
        bounds: impl Fn(usize) -> Bounds3 + Sync,
        packed: impl Fn(usize) -> bool + Sync,
        parallel_from: usize,
        method: BuildMethod,
        leaves: Leaves,
    ) -> Self {
        let (mut items, root) = items_of(count, bounds, packed);
        let codes = match method {
            BuildMethod::Morton => morton_order(&mut items),
            BuildMethod::Sah => vec![],
        };
        let mut tree = Tree::reserved(count);
        if !items.is_empty() {
            // A node's slab test costs about what a packet's test does, an eighth of a
            // triangle's (pbrt's ratio).
            let packets = items.iter().any(|it| it.packed);
            let split = match method {
                BuildMethod::Sah => Split::Sah { traversal: if packets { 1.0 } else { 0.125 } },
                BuildMethod::Morton => Split::Morton { codes: &codes },
            };
            let all = Summary::of(&items);
            tree.build(&mut items, 0, all, 0, split, parallel_from, leaves);
        }
        let mut bvh = Bvh { root, ..Bvh::default() };
        // Every item lies in one leaf, the leaves in item order: the items' indices are the
        // leaf order.
        items.par_iter().map(|it| it.index).collect_into_vec(&mut bvh.order);
        (bvh.wide, bvh.start) = wide::collapse(&tree);
        bvh.reach = std::array::from_fn(|a| {
            let (lo, hi) = (wide::down(bvh.root.min[a]) as f64, wide::up(bvh.root.max[a]) as f64);
            if items.is_empty() { 0.0 } else { lo.abs().max(hi.abs()) }
        });
        bvh
    }

    /// Visits candidate primitives front to back. `visit(index, t_max)` returns a closer hit
    /// distance, which prunes the rest of the traversal; `Some(0.0)` ends it at once (for
    /// any-hit queries such as shadow rays). Not after [`Self::relabel_leaves`].
    #[inline]
    pub fn traverse(&self, ray: &Ray, t_max: f64, mut visit: impl FnMut(u32, f64) -> Option<f64>) -> f64 {
        assert!(!self.relabeled, "the leaves' labels no longer index the primitives");
        self.traverse_leaves(ray, t_max, |leaf, mut t_max| {
            let mut closer = None;
            for &prim in &self.order[leaf] {
                if let Some(t) = visit(prim, t_max) {
                    if t <= 0.0 {
                        return Some(0.0);
                    }
                    t_max = t_max.min(t);
                    closer = Some(t_max);
                }
            }
            closer
        })
    }

    /// Visits candidate leaves nearest entry first: `visit(labels, t_max)` gets the leaf's
    /// labels (its positions in [`Self::leaf_order`] unless relabelled) and returns a closer
    /// hit distance, or `Some(0.0)` to stop. Leaves the ray enters beyond the closest hit so far
    /// are skipped.
    #[inline]
    pub fn traverse_leaves(
        &self,
        ray: &Ray,
        t_max: f64,
        visit: impl FnMut(std::ops::Range<usize>, f64) -> Option<f64>,
    ) -> f64 {
        self.traverse_leaves_prefetching(ray, t_max, |_| {}, visit)
    }

    /// True when the whole tree is one leaf: traversal tests no node.
    pub fn is_one_leaf(&self) -> bool {
        self.start.is_none_or(|e| e.is_leaf())
    }

    /// [`Self::traverse_leaves`], calling `prefetch(labels)` for each leaf as soon as the ray is
    /// found to meet its box, before it is visited: the caller can start loading what the leaf
    /// holds while the traversal goes on.
    #[inline]
    #[allow(unsafe_code)]
    pub fn traverse_leaves_prefetching(
        &self,
        ray: &Ray,
        t_max: f64,
        prefetch: impl Fn(std::ops::Range<usize>),
        visit: impl FnMut(std::ops::Range<usize>, f64) -> Option<f64>,
    ) -> f64 {
        // SAFETY: without AVX2.
        unsafe { self.traverse_leaves_prefetching_with::<false, true>(ray, t_max, prefetch, visit) }
    }

    /// [`Self::traverse_leaves_prefetching`] with each node's eight children tested in one
    /// AVX2 register when `AVX2`: the same leaves in the same order. Fast where the caller is
    /// compiled for AVX2 (`#[target_feature(enable = "avx2")]`), so the node test is inlined.
    /// Without `NEAREST` the children met are visited in slot order, not sorted by distance:
    /// for a visit that only asks whether some leaf holds a hit (it returns `Some(0.0)` or
    /// `None`), which leaf answers first cannot change the answer.
    ///
    /// # Safety
    /// `AVX2` only on a processor with AVX2.
    #[inline(always)]
    #[allow(unsafe_code)]
    pub unsafe fn traverse_leaves_prefetching_with<const AVX2: bool, const NEAREST: bool>(
        &self,
        ray: &Ray,
        mut t_max: f64,
        prefetch: impl Fn(std::ops::Range<usize>),
        mut visit: impl LeafVisit,
    ) -> f64 {
        let Some(mut at) = self.start else { return t_max };
        if at.is_leaf() {
            // A lone leaf is tested whole: its box test would only cost a division.
            return visit.visit(at.labels(), t_max).map_or(t_max, |t| t_max.min(t.max(0.0)));
        }
        // SAFETY: the caller's contract.
        let slab = unsafe { Slab::of::<AVX2>(ray, self.reach) };
        let mut limit = wide::up(t_max);
        // Not zeroed: a traversal of a small tree would spend longer clearing it than using it.
        let mut stack = [const { std::mem::MaybeUninit::<Entry>::uninit() }; STACK];
        let mut sp = 0;
        // A child met is asked of memory before it is visited: a leaf's contents or a node.
        let ask_memory = |child: Entry| {
            if child.is_leaf() {
                prefetch(child.labels());
            } else {
                Slab::prefetch(&self.wide[child.offset as usize]);
            }
        };
        loop {
            if at.is_leaf() {
                if let Some(t) = visit.visit(at.labels(), t_max) {
                    if t <= 0.0 {
                        return 0.0;
                    }
                    t_max = t_max.min(t);
                    limit = wide::up(t_max);
                }
            } else {
                let node = &self.wide[at.offset as usize];
                // SAFETY: the caller's contract.
                let (hits, near) = unsafe { slab.test::<AVX2>(node, limit) };
                if hits != 0 && hits & (hits - 1) == 0 {
                    // One child met: descended into at once.
                    let k = hits.trailing_zeros() as usize;
                    at = Slab::child(node, k, near[k]);
                    continue;
                }
                if hits.count_ones() == 2 {
                    // Two: the nearer descended into (the first in slot order on a tie), the
                    // other waits; both asked of memory.
                    let (a, b) = (hits.trailing_zeros() as usize, (hits & (hits - 1)).trailing_zeros() as usize);
                    let (first, second) = if NEAREST && near[b] < near[a] { (b, a) } else { (a, b) };
                    let later = Slab::child(node, second, near[second]);
                    stack[sp].write(later);
                    sp += 1;
                    at = Slab::child(node, first, near[first]);
                    ask_memory(at);
                    ask_memory(later);
                    continue;
                }
                if hits != 0 && !NEAREST {
                    // Slot order: the first descended into, the rest wait (asked of memory).
                    let k = hits.trailing_zeros() as usize;
                    let mut rest = hits & (hits - 1);
                    while rest != 0 {
                        let j = 31 - rest.leading_zeros() as usize;
                        rest &= !(1 << j);
                        let child = Slab::child(node, j, near[j]);
                        stack[sp].write(child);
                        sp += 1;
                        ask_memory(child);
                    }
                    at = Slab::child(node, k, near[k]);
                    continue;
                }
                if hits != 0 {
                    // The children met, nearest first (ties in slot order); the rest wait.
                    let (met, n) = wide::nearest_first(hits, &near);
                    for &key in met[1..n].iter().rev() {
                        let k = wide::slot_of(key);
                        stack[sp].write(Slab::child(node, k, near[k]));
                        sp += 1;
                    }
                    // Load the nodes met while the nearest is descended into.
                    for &key in &met[..n] {
                        ask_memory(Slab::child(node, wide::slot_of(key), 0.0));
                    }
                    let k = wide::slot_of(met[0]);
                    at = Slab::child(node, k, near[k]);
                    continue;
                }
            }
            loop {
                if sp == 0 {
                    return t_max;
                }
                sp -= 1;
                // SAFETY: every slot below `sp` was written before `sp` passed it.
                #[allow(unsafe_code)]
                {
                    at = unsafe { stack[sp].assume_init() };
                }
                if at.near as f64 <= t_max {
                    break;
                }
            }
        }
    }

    /// Rewrites the labels traversal reports for each leaf: `relabel(primitives)` for every
    /// leaf's primitive indices, once (a mesh makes them its packets, the world its leaves).
    /// Afterwards [`Self::traverse`] is refused and [`Self::leaves`] lists the new labels.
    pub fn relabel_leaves(&mut self, mut relabel: impl FnMut(&[u32]) -> std::ops::Range<usize>) {
        let order = std::mem::take(&mut self.order);
        self.relabel_leaf_ranges(|leaf| relabel(&order[leaf]));
        self.order = order;
    }

    /// [`Self::relabel_leaves`] by each leaf's range in [`Self::leaf_order`]: `relabel(range)`.
    pub fn relabel_leaf_ranges(&mut self, mut relabel: impl FnMut(std::ops::Range<usize>) -> std::ops::Range<usize>) {
        assert!(!self.relabeled, "leaves are relabelled once");
        self.relabeled = true;
        wide::relabel(&mut self.wide, &mut self.start, |e| {
            let r = relabel(e.labels());
            (r.start as u32, r.len() as u32)
        });
    }

    /// Primitive indices in leaf order: leaf `k`'s primitives are `leaf_order()[range]` for
    /// the ranges [`Self::leaves`] lists and [`Self::traverse_leaves`] visits.
    pub fn leaf_order(&self) -> &[u32] {
        &self.order
    }

    /// Every leaf's range in [`Self::leaf_order`].
    pub fn leaves(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        let wide = self.wide.iter().flat_map(|w| (0..WIDTH).map(|k| Slab::child(w, k, 0.0)));
        self.start.into_iter().chain(wide).filter(|e| e.is_leaf() && e.count != u32::MAX).map(|e| e.labels())
    }

    /// The bounds of everything (empty for an empty BVH).
    pub fn bounds(&self) -> Bounds3 {
        self.root
    }
}

/// Four `f32` lanes: x, y, z and a copy of z, so that a box's corners and an item's centroid
/// are one register each and the binning's minima, maxima and sums are one instruction.
type Lanes4 = [f32; 4];

#[inline(always)]
fn min4(a: Lanes4, b: Lanes4) -> Lanes4 {
    // `b < a ? b : a` keeps the accumulator `a` when `b` is NaN (MINPS's rule).
    std::array::from_fn(|k| if b[k] < a[k] { b[k] } else { a[k] })
}

#[inline(always)]
fn max4(a: Lanes4, b: Lanes4) -> Lanes4 {
    std::array::from_fn(|k| if b[k] > a[k] { b[k] } else { a[k] })
}

/// What one pass over a node's items finds: their bounds, the bounds of their centroids
/// (doubled: `min + max` in `f32`, the binning's coordinate) and the tests a leaf of them would
/// cost. All in `f32`: the items' boxes are, so their unions are exact.
#[derive(Clone, Copy)]
struct Summary {
    lo: Lanes4,
    hi: Lanes4,
    centroid_lo: Lanes4,
    centroid_hi: Lanes4,
    tests: Tests,
}

impl Summary {
    const EMPTY: Self = Self {
        lo: [f32::INFINITY; 4],
        hi: [f32::NEG_INFINITY; 4],
        centroid_lo: [f32::INFINITY; 4],
        centroid_hi: [f32::NEG_INFINITY; 4],
        tests: Tests { packed: 0, single: 0 },
    };

    fn of(items: &[Item]) -> Self {
        items.iter().fold(Self::EMPTY, Self::add)
    }

    fn add(self, it: &Item) -> Self {
        let (lo, hi) = it.lanes();
        self.add_lanes(it, lo, hi, doubled_centroid(lo, hi))
    }

    /// [`Self::add`] for an item whose box is `lo`, `hi` and doubled centroid `centroid`.
    #[inline(always)]
    fn add_lanes(self, it: &Item, lo: Lanes4, hi: Lanes4, centroid: Lanes4) -> Self {
        Self {
            lo: min4(self.lo, lo),
            hi: max4(self.hi, hi),
            centroid_lo: min4(self.centroid_lo, centroid),
            centroid_hi: max4(self.centroid_hi, centroid),
            tests: self.tests.add(it),
        }
    }

    fn merge(self, o: &Self) -> Self {
        Self {
            lo: min4(self.lo, o.lo),
            hi: max4(self.hi, o.hi),
            centroid_lo: min4(self.centroid_lo, o.centroid_lo),
            centroid_hi: max4(self.centroid_hi, o.centroid_hi),
            tests: self.tests.merge(o.tests),
        }
    }

    /// The items' bounds.
    fn bounds(&self) -> Bounds3 {
        f32_box(&self.lo, &self.hi)
    }
}

/// Twice an item's centroid, `lo + hi`, rounded to `f32`.
#[inline(always)]
fn doubled_centroid(lo: Lanes4, hi: Lanes4) -> Lanes4 {
    std::array::from_fn(|k| lo[k] + hi[k])
}

/// The binned SAH split of `items` (partitioned in place): the first item of the second half
/// and, when the halves are the bins', their summaries.
fn sah_split(items: &mut [Item], node: &Summary, traversal: f64, pack: usize) -> Option<(usize, Option<[Summary; 2]>)> {
    let extent: [f32; 3] = std::array::from_fn(|a| node.centroid_hi[a] - node.centroid_lo[a]);
    let axis = if extent[0] >= extent[1] && extent[0] >= extent[2] {
        0
    } else if extent[1] >= extent[2] {
        1
    } else {
        2
    };
    if extent[axis] <= 0.0 || !extent[axis].is_finite() {
        // All centroids coincide: split in the middle to keep leaves small.
        if items.len() > 255 {
            return Some((items.len() / 2, None));
        }
        return None;
    }
    let (lo, per_unit) = (node.centroid_lo[axis], BINS as f32 / extent[axis]);
    let bins = match axis {
        0 => bin_items::<0>(items, lo, per_unit),
        1 => bin_items::<1>(items, lo, per_unit),
        _ => bin_items::<2>(items, lo, per_unit),
    };
    // Sweep from the right to get suffix areas, then from the left.
    let mut right_area = [0.0; BINS];
    let mut acc = Summary::EMPTY;
    for i in (1..BINS).rev() {
        acc = acc.merge(&bins[i]);
        right_area[i] = acc.bounds().surface_area() * acc.tests.cost(pack);
    }
    let (mut best, mut best_cost) = (0, f64::INFINITY);
    let mut left = Summary::EMPTY;
    for i in 0..BINS - 1 {
        left = left.merge(&bins[i]);
        let cost = left.bounds().surface_area() * left.tests.cost(pack) + right_area[i + 1];
        if cost < best_cost {
            best_cost = cost;
            best = i;
        }
    }
    let area = node.bounds().surface_area();
    let leaf_cost = node.tests.cost(pack) * area;
    let split_cost = traversal * area + best_cost;
    if split_cost >= leaf_cost && items.len() <= 255 {
        return None;
    }
    let mid = partition(items, |it| usize::from(it.bin) <= best);
    if mid == 0 || mid == items.len() {
        return Some((items.len() / 2, None));
    }
    let halves = [&bins[..=best], &bins[best + 1..]].map(|b| b.iter().fold(Summary::EMPTY, |s, b| s.merge(b)));
    Some((mid, Some(halves)))
}

/// The items' doubled centroids put in [`BINS`] equal slices, from `lo` at `per_unit` slices a
/// unit along axis `AXIS` (each item keeping its bin), and each bin's summary.
fn bin_items<const AXIS: usize>(items: &mut [Item], lo: f32, per_unit: f32) -> [Summary; BINS] {
    // Four sets of bins, item by item in turn, merged after: neighbouring items fall in the
    // same bin, and one set would make each update wait for the last one's store.
    let mut sets = [[Summary::EMPTY; BINS]; 4];
    for (k, it) in items.iter_mut().enumerate() {
        let (l, h) = it.lanes();
        let c = doubled_centroid(l, h);
        // At or above 0 (c ≥ lo); `as i32` saturates (and takes NaN to 0).
        let bin = (((c[AXIS] - lo) * per_unit) as i32).clamp(0, BINS as i32 - 1) as usize;
        it.bin = bin as u8;
        let set = &mut sets[k % 4][bin];
        *set = set.add_lanes(it, l, h, c);
    }
    std::array::from_fn(|i| sets.iter().fold(Summary::EMPTY, |s, set| s.merge(&set[i])))
}

/// What the heuristic charges for a leaf: one test per started group of `pack` packed
/// primitives, plus one per other primitive; leaves costing at most `max_tests` are not split.
/// The same on every processor, so the tree (and with it which of two equally near hits wins)
/// is the same everywhere.
#[derive(Clone, Copy, Debug)]
struct Leaves {
    pack: usize,
    max_tests: usize,
    /// A whole set costing at most this many tests, its packets at most `max_tests`, is one
    /// leaf (the root is not split).
    whole: usize,
}

impl Leaves {
    /// A mesh's flats, eight to a packet: charged four to a test (a leaf of up to sixteen is
    /// not split). Charging eight, with leaves of up to eight or sixteen, measured no faster
    /// (session 32, `BENCHMARKS.md`).
    const MESH: Self = Self { pack: 4, max_tests: 4, whole: 0 };
    /// The world's flats and spheres, eight to a packet: charged eight to a test, leaves of up
    /// to sixteen not split (so a still life of a few dozen objects stays a leaf or two).
    const WORLD: Self = Self { pack: 8, max_tests: 2, whole: 0 };
}

/// A node's split rule.
#[derive(Clone, Copy)]
enum Split<'a> {
    /// The surface area heuristic, a node's test costing `traversal` primitive tests.
    Sah { traversal: f64 },
    /// Morton order: the items sorted by their Morton `codes` (one per item of the node).
    Morton { codes: &'a [u64] },
}

impl<'a> Split<'a> {
    /// The rules of the two halves when a node's items split at `mid`.
    fn split_at(self, mid: usize) -> (Self, Self) {
        match self {
            Split::Sah { .. } => (self, self),
            Split::Morton { codes } => {
                let (left, right) = codes.split_at(mid);
                (Split::Morton { codes: left }, Split::Morton { codes: right })
            }
        }
    }
}

/// Width of the chunks in which [`items_of`] makes the items on all threads.
const ITEM_CHUNK: usize = 4096;

/// The items of primitives `0..count` and the exact union of their `bounds`, made in one pass
/// on all threads (the union is of minima and maxima: the same bits in any order).
fn items_of(
    count: usize,
    bounds: impl Fn(usize) -> Bounds3 + Sync,
    packed: impl Fn(usize) -> bool + Sync,
) -> (Vec<Item>, Bounds3) {
    let mut items: Vec<Item> = Vec::with_capacity(count);
    let root = items.spare_capacity_mut()[..count]
        .par_chunks_mut(ITEM_CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let mut root = Bounds3::EMPTY;
            for (k, slot) in chunk.iter_mut().enumerate() {
                let i = c * ITEM_CHUNK + k;
                let b = bounds(i);
                root = root.union(b);
                slot.write(Item::new(i, b, packed(i)));
            }
            root
        })
        .reduce(|| Bounds3::EMPTY, Bounds3::union);
    // SAFETY: the chunks cover the first `count` slots, and each slot was written above.
    #[allow(unsafe_code)]
    unsafe {
        items.set_len(count)
    };
    (items, root)
}

/// Bits of a Morton code per axis.
const MORTON_BITS: u32 = 21;

/// Sorts the items by the Morton code of their centroids within the centroids' bounds (ties by
/// index: the order is a function of the input); returns the codes in that order.
fn morton_order(items: &mut Vec<Item>) -> Vec<u64> {
    let cb = items.iter().fold(Bounds3::EMPTY, |b, it| b.grow(it.bounds().centroid()));
    let extent = cb.extent();
    let scale = ((1u64 << MORTON_BITS) - 1) as f64;
    let quantise = |x: f64, lo: f64, e: f64| if e > 0.0 { ((x - lo) / e * scale).clamp(0.0, scale) as u64 } else { 0 };
    let code = |it: &Item| {
        let c = it.bounds().centroid();
        let q: [u64; 3] = std::array::from_fn(|a| quantise(c[a], cb.min[a], extent[a]));
        (0..MORTON_BITS).fold(0, |code, bit| {
            code | ((q[0] >> bit) & 1) << (3 * bit + 2)
                | ((q[1] >> bit) & 1) << (3 * bit + 1)
                | ((q[2] >> bit) & 1) << (3 * bit)
        })
    };
    let mut keyed: Vec<(u64, Item)> = items.drain(..).map(|it| (code(&it), it)).collect();
    keyed.sort_unstable_by_key(|(code, it)| (*code, it.index));
    let codes = keyed.iter().map(|(code, _)| *code).collect();
    items.extend(keyed.into_iter().map(|(_, it)| it));
    codes
}

/// The split of Morton-sorted items, given by their `codes`, where the codes first differ (the
/// highest bit on which the first and last disagree), in the middle when all codes are equal.
fn morton_split(codes: &[u64]) -> usize {
    let (first, last) = (codes[0], codes[codes.len() - 1]);
    if first == last {
        return codes.len() / 2;
    }
    let bit = 63 - (first ^ last).leading_zeros();
    codes.partition_point(|code| code & (1 << bit) == 0)
}

/// Moves the items for which `pred` holds before the others (Hoare's two-ended scan: each
/// misplaced pair swapped once); returns how many there are.
fn partition(items: &mut [Item], pred: impl Fn(&Item) -> bool) -> usize {
    let (mut i, mut j) = (0, items.len());
    loop {
        while i < j && pred(&items[i]) {
            i += 1;
        }
        while i < j && !pred(&items[j - 1]) {
            j -= 1;
        }
        if i == j {
            return i;
        }
        items.swap(i, j - 1);
        (i, j) = (i + 1, j - 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `count` boxes of half-extents up to `size` centred in a cube of side 100, drawn by a
    /// xorshift generator from `seed` (not 0).
    fn scattered_boxes(seed: u64, count: usize, size: f64) -> Vec<Bounds3> {
        let mut state = seed;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..count)
            .map(|_| {
                let c = Vec3::new(next(), next(), next()) * 100.0;
                let r = Vec3::new(next(), next(), next()) * size;
                Bounds3 { min: c - r, max: c + r }
            })
            .collect()
    }

    proptest::proptest! {
        /// The two-ended partition moves the items that satisfy the predicate before the
        /// others, loses none and duplicates none, and says how many there are.
        #[test]
        fn partition_splits_by_the_predicate(bins in proptest::collection::vec(0u8..12, 0..200), best in 0u8..12) {
            let mut items: Vec<Item> = bins
                .iter()
                .enumerate()
                .map(|(i, &bin)| Item { bin, ..Item::new(i, Bounds3::EMPTY, false) })
                .collect();
            let mid = partition(&mut items, |it| it.bin <= best);
            proptest::prop_assert_eq!(mid, bins.iter().filter(|&&b| b <= best).count());
            proptest::prop_assert!(items[..mid].iter().all(|it| it.bin <= best));
            proptest::prop_assert!(items[mid..].iter().all(|it| it.bin > best));
            let mut seen: Vec<u32> = items.iter().map(|it| it.index).collect();
            seen.sort_unstable();
            proptest::prop_assert!(seen.iter().copied().eq(0..bins.len() as u32));
            proptest::prop_assert!(items.iter().all(|it| bins[it.index as usize] == it.bin));
        }
    }

    proptest::proptest! {
        /// The any-hit walk meets the leaves the nearest-first walk meets, only in another
        /// order: with a visit that never stops, the same set; with one that stops at a leaf,
        /// the same answer (a leaf was met or none).
        #[test]
        fn any_leaf_walk_meets_the_leaves_of_the_nearest_first_walk(
            seed in 1u64..u64::MAX,
            origin in proptest::array::uniform3(-20.0..120.0f64),
            dir in proptest::array::uniform3(-1.0..1.0f64),
            t_max in 1.0..300.0f64,
            stop in 0usize..40,
        ) {
            let bounds = scattered_boxes(seed, 300, 4.0);
            let bvh = Bvh::build(&bounds);
            let ray = Ray::new(Vec3::from(origin), Vec3::from(dir));
            #[cfg(target_arch = "x86_64")]
            let avx2 = std::arch::is_x86_feature_detected!("avx2");
            #[cfg(not(target_arch = "x86_64"))]
            let avx2 = false;
            let walks = |nearest: bool, stop_at: Option<usize>| {
                let mut met = Vec::new();
                let visit = |labels: std::ops::Range<usize>, _| {
                    met.push(labels.start);
                    (Some(met.len()) == stop_at).then_some(0.0)
                };
                // SAFETY: AVX2 only where the processor has it.
                #[allow(unsafe_code)]
                let t = unsafe {
                    match (nearest, avx2) {
                        (true, true) => bvh.traverse_leaves_prefetching_with::<true, true>(&ray, t_max, |_| {}, visit),
                        (true, false) => bvh.traverse_leaves_prefetching_with::<false, true>(&ray, t_max, |_| {}, visit),
                        (false, true) => bvh.traverse_leaves_prefetching_with::<true, false>(&ray, t_max, |_| {}, visit),
                        (false, false) => bvh.traverse_leaves_prefetching_with::<false, false>(&ray, t_max, |_| {}, visit),
                    }
                };
                (met, t)
            };
            let (mut nearest, _) = walks(true, None);
            let (mut any, _) = walks(false, None);
            nearest.sort_unstable();
            any.sort_unstable();
            proptest::prop_assert_eq!(&nearest, &any);
            let stopped = |nearest| walks(nearest, Some(stop)).1 == 0.0;
            proptest::prop_assert_eq!(stopped(true), stopped(false));
            proptest::prop_assert_eq!(stopped(false), stop >= 1 && stop <= any.len());
        }
    }

    /// A set costing at most `whole` tests is one leaf where the SAH splits it; one costing
    /// more is split as before (its tree unchanged below the root).
    #[test]
    fn a_set_within_whole_is_one_leaf() {
        // Ten boxes far apart in a row, two of them packed (one test between them): 9 tests.
        let bounds: Vec<Bounds3> = (0..10)
            .map(|k| Bounds3 {
                min: Vec3::new(10.0 * k as f64, 0.0, 0.0),
                max: Vec3::new(10.0 * k as f64 + 1.0, 1.0, 1.0),
            })
            .collect();
        let packed = |i: usize| i < 2;
        assert!(!Bvh::build_packed(&bounds, packed).is_one_leaf());
        for (whole, one) in [(8, false), (9, true), (12, true)] {
            let bvh = Bvh::build_packed_within(&bounds, packed, whole);
            assert_eq!(bvh.is_one_leaf(), one, "within {whole}");
            assert_eq!(bvh.leaves().count(), if one { 1 } else { Bvh::build_packed(&bounds, packed).leaves().count() });
        }
        // All packed, three packets (three tests, more than a leaf's two): split however few.
        let all_packed = |_: usize| true;
        let many: Vec<Bounds3> = (0..24).map(|k| bounds[k % 10]).collect();
        assert!(!Bvh::build_packed_within(&many, all_packed, 12).is_one_leaf());
    }

    /// Building subtrees on several threads lays out the very tree one thread builds.
    #[test]
    fn parallel_build_is_the_sequential_tree() {
        let bounds = scattered_boxes(0x9e3779b97f4a7c15, 50_000, 1.0);
        for method in [BuildMethod::Sah, BuildMethod::Morton] {
            let sequential =
                Bvh::build_split_from(bounds.len(), |i| bounds[i], |i| i % 3 == 0, usize::MAX, method, Leaves::WORLD);
            let parallel =
                Bvh::build_split_from(bounds.len(), |i| bounds[i], |i| i % 3 == 0, 256, method, Leaves::WORLD);
            assert_eq!(sequential.order, parallel.order);
            assert_eq!(sequential.wide, parallel.wide);
            assert!(sequential.wide.len() > 300);
        }
    }
}
