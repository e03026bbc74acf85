//! Piecewise-constant distributions in one and two dimensions, for choosing light sources,
//! emitting triangles and environment-map texels in proportion to their power. Inverting the
//! CDF starts from a guide table (Chen and Asau 1974; Devroye 1986, §III.2.4): for each of
//! `n` equal slices of `[0, 1)`, the cells its ends fall in, so the search is confined to the
//! few cells a slice spans — the very cell a search of the whole CDF finds, in about one step
//! instead of log₂ n dependent loads.

/// Distributions of at most this many cells are searched without a guide table.
const GUIDED_FROM: usize = 16;

/// A piecewise-constant density on `[0, 1)` with `n` equal cells.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f64>,
    cdf: Vec<f64>,
    integral: f64,
    /// `guide[j]`: how many CDF entries are at most the start of slice `j` ([`Slices`]), for `j` in `0..=n`;
    /// empty for few cells, which are searched whole.
    guide: Vec<u32>,
    slices: Slices,
}

impl Distribution1D {
    /// From non-negative cell weights (all zero gives the uniform distribution).
    pub fn new(weights: &[f64]) -> Self {
        let n = weights.len().max(1);
        let mut func: Vec<f64> = weights.iter().map(|w| if w.is_finite() { w.max(0.0) } else { 0.0 }).collect();
        func.resize(n, 0.0);
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        for w in &func {
            cdf.push(cdf.last().unwrap() + w / n as f64);
        }
        let mut integral = cdf[n];
        if integral <= 0.0 {
            func.iter_mut().for_each(|f| *f = 1.0);
            cdf.iter_mut().enumerate().for_each(|(i, c)| *c = i as f64 / n as f64);
            integral = 1.0;
        } else {
            cdf.iter_mut().for_each(|c| *c /= integral);
        }
        let mut d = Self { func, cdf, integral, guide: vec![], slices: Slices::new(n) };
        if n <= GUIDED_FROM {
            return d;
        }
        d.guide = guide_table(n, |i| d.cdf[i]).map(|g| g as u32).collect();
        d
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// True when there are no cells (never: at least one cell exists).
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// `∫ f` over `[0, 1)`.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The cell of the last CDF entry `≤ u` ([`search_cdf`] with this distribution's table).
    fn cell(&self, u: f64) -> usize {
        let guide = (!self.guide.is_empty()).then_some((&self.slices, |j: usize| self.guide[j] as usize));
        search_cdf(u, self.func.len(), guide, |i| self.cdf[i])
    }

    /// A cell with probability proportional to its weight, and that probability.
    pub fn sample_discrete(&self, u: f64) -> (usize, f64) {
        let i = self.cell(u);
        (i, self.discrete_pdf(i))
    }

    /// Probability of cell `i` in [`Self::sample_discrete`].
    pub fn discrete_pdf(&self, i: usize) -> f64 {
        self.func[i] / (self.integral * self.func.len() as f64)
    }

    /// A point in `[0, 1)` with density `f/∫f`, its density and cell.
    pub fn sample_continuous(&self, u: f64) -> (f64, f64, usize) {
        let (x, i) = self.sample_point(u);
        (x, self.cell_density(i), i)
    }

    /// The density `f/∫f` on cell `i`.
    pub fn cell_density(&self, i: usize) -> f64 {
        self.func[i] / self.integral
    }

    /// [`Self::sample_continuous`]'s point and cell without its density (the CDF alone is read:
    /// callers that keep densities beside their own data save a cache line).
    pub fn sample_point(&self, u: f64) -> (f64, usize) {
        let i = self.cell(u);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 { (u - self.cdf[i]) / width } else { 0.5 };
        ((((i as f64 + du.clamp(0.0, 1.0)) / self.func.len() as f64).min(1.0 - 1e-16)), i)
    }

    /// Density at `x ∈ [0, 1)`.
    pub fn pdf(&self, x: f64) -> f64 {
        self.cell_density(((x * self.func.len() as f64) as usize).min(self.func.len() - 1))
    }
}

/// `n` equal slices of `[0, 1)`, their width computed once: a search finds its slice without
/// a division or the long conversions of `usize` (x86-64 has signed ones only).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Slices {
    n: usize,
    count: f64,
    width: f64,
}

impl Slices {
    pub fn new(n: usize) -> Self {
        Slices { n, count: n as f64, width: 1.0 / n as f64 }
    }

    /// The start of slice `j`: about `j / n`, the same bits wherever computed, which is all a
    /// guide table needs.
    #[inline(always)]
    fn start(&self, j: usize) -> f64 {
        j as i64 as f64 * self.width
    }

    /// The slice holding `u`: `u·n` rounded down, mended where that rounds across a slice's
    /// edge. The mending is rare and out of line: inlined, the compiler vectorised its loops
    /// into a long preamble every search ran through.
    #[inline(always)]
    pub fn of(&self, u: f64) -> usize {
        // Saturating as `as usize` does: NaN and below zero to 0.
        let j = (((u * self.count) as i64).max(0) as usize).min(self.n - 1);
        let below = j > 0 && u < self.start(j);
        let above = j + 1 < self.n && u >= self.start(j + 1);
        if below || above { self.mend(u, j) } else { j }
    }

    #[cold]
    #[inline(never)]
    fn mend(&self, u: f64, mut j: usize) -> usize {
        while j > 0 && u < self.start(j) {
            j -= 1;
        }
        while j + 1 < self.n && u >= self.start(j + 1) {
            j += 1;
        }
        j
    }
}

/// The guide table of a non-decreasing CDF of `n + 1` entries read by `entry`: for each slice
/// start `j` in `0..=n`, how many entries are at most it.
pub(crate) fn guide_table(n: usize, entry: impl Fn(usize) -> f64) -> impl Iterator<Item = usize> {
    let (mut at, slices) = (0, Slices::new(n));
    (0..=n).map(move |j| {
        let edge = slices.start(j);
        while at <= n && entry(at) <= edge {
            at += 1;
        }
        at
    })
}

/// The cell (in `0..n`) of the last of a CDF's `n + 1` entries `≤ u`, the entries read by
/// `entry`. With a guide table ([`guide_table`], read by `guide`) the entries `≤ u` are those
/// up to the start of `u`'s slice and some of those before its end, so only the few cells the
/// slice spans are searched; without one, the whole CDF.
#[inline]
pub(crate) fn search_cdf(
    u: f64,
    n: usize,
    guide: Option<(&Slices, impl Fn(usize) -> usize)>,
    entry: impl Fn(usize) -> f64,
) -> usize {
    let (mut lo, mut hi) = (0, n + 1);
    if let Some((slices, guide)) = guide {
        let j = slices.of(u);
        lo = if j == 0 { 0 } else { guide(j) };
        hi = if j + 1 < n { guide(j + 1) } else { n + 1 };
    }
    // The first entry in lo..hi above u (or hi), in [lo, lo + len]: the range halved by a
    // count of steps that depends on its length alone, each step a conditional move rather
    // than a branch on the entries (which the processor cannot predict).
    let mut len = hi - lo;
    while len > 1 {
        let half = len / 2;
        lo = if entry(lo + half - 1) <= u { lo + half } else { lo };
        len -= half;
    }
    if len == 1 && entry(lo) <= u {
        lo += 1;
    }
    lo.saturating_sub(1).min(n - 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::Just;

    #[test]
    fn samples_follow_the_weights() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0, 4.0]);
        let mut counts = [0usize; 4];
        let n = 80_000;
        for k in 0..n {
            let (x, pdf, i) = d.sample_continuous((k as f64 + 0.5) / n as f64);
            assert!((d.pdf(x) - pdf).abs() < 1e-12);
            counts[i] += 1;
        }
        for (i, w) in [1.0, 0.0, 3.0, 4.0].iter().enumerate() {
            assert!((counts[i] as f64 / n as f64 - w / 8.0).abs() < 1e-3, "{counts:?}");
        }
        assert!((d.discrete_pdf(3) - 0.5).abs() < 1e-12);
    }

    proptest::proptest! {
        /// The guided search finds the cell a search of the whole CDF finds, for any weights
        /// (zeros, spikes, one cell) and any u, ends and beyond included.
        #[test]
        fn guided_search_is_the_whole_search(
            weights in proptest::collection::vec(proptest::prop_oneof![Just(0.0), 0.0..1.0f64, 1e6..1e9f64], 1..100),
            us in proptest::collection::vec(-0.1..1.1f64, 1..60),
        ) {
            let d = Distribution1D::new(&weights);
            let mut us = us;
            us.extend(d.cdf.iter().copied().chain((0..=d.len()).map(|j| d.slices.start(j))));
            us.extend([0.0, 1.0, 1.0 - 1e-16, f64::NAN, f64::INFINITY, -0.0]);
            for u in us {
                let whole = d.cdf.partition_point(|&c| c <= u).saturating_sub(1).min(d.len() - 1);
                proptest::prop_assert_eq!(d.cell(u), whole, "u = {}", u);
                // The slice as a division would give it: the last start at or below `u`.
                let n = d.len();
                let by_division = (0..n).rfind(|&j| j == 0 || u >= j as f64 * (1.0 / n as f64)).unwrap();
                proptest::prop_assert_eq!(d.slices.of(u), if u >= 0.0 { by_division } else { 0 }, "u = {}", u);
            }
        }
    }
}
