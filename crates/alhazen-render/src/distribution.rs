//! Piecewise-constant distributions in one and two dimensions, for choosing light sources,
//! emitting triangles and environment-map texels in proportion to their power. Inverting the
//! CDF starts from a guide table (Chen and Asau 1974; Devroye 1986, §III.2.4): for each of
//! `n` equal slices of `[0, 1)`, the cells its ends fall in, so the search is confined to the
//! few cells a slice spans — the very cell a search of the whole CDF finds, in about one step
//! instead of log₂ n dependent loads.

use alhazen_math::Vec2;

/// Distributions of at most this many cells are searched without a guide table.
const GUIDED_FROM: usize = 16;

/// A piecewise-constant density on `[0, 1)` with `n` equal cells.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f64>,
    cdf: Vec<f64>,
    integral: f64,
    /// `guide[j]`: how many CDF entries are at most [`Self::edge`]`(j)`, for `j` in `0..=n`;
    /// empty for few cells, which are searched whole.
    guide: Vec<u32>,
    /// `1 / n`.
    slice: f64,
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
        let mut d = Self { func, cdf, integral, guide: vec![], slice: 1.0 / n as f64 };
        if n <= GUIDED_FROM {
            return d;
        }
        let mut at = 0;
        d.guide = (0..=n)
            .map(|j| {
                let edge = d.edge(j);
                while at < d.cdf.len() && d.cdf[at] <= edge {
                    at += 1;
                }
                at as u32
            })
            .collect();
        d
    }

    /// The start of slice `j` of the guide table (about `j / n`, the same bits wherever
    /// computed, which is all the table needs).
    #[inline]
    fn edge(&self, j: usize) -> f64 {
        j as f64 * self.slice
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

    /// The cell of the last CDF entry `≤ u`: the entries `≤ u` are those up to slice
    /// `j`'s start (`guide[j]`) and some of those before its end (`guide[j + 1]`).
    fn cell(&self, u: f64) -> usize {
        let n = self.func.len();
        if self.guide.is_empty() {
            return self.cdf.partition_point(|&c| c <= u).saturating_sub(1).min(n - 1);
        }
        // The slice holding u, mended where u·n rounds across a slice's edge.
        let mut j = ((u * n as f64) as usize).min(n - 1);
        while j > 0 && u < self.edge(j) {
            j -= 1;
        }
        while j + 1 < n && u >= self.edge(j + 1) {
            j += 1;
        }
        let lo = if j == 0 { 0 } else { self.guide[j] as usize };
        let hi = if j + 1 < n { self.guide[j + 1] as usize } else { self.cdf.len() };
        let i = lo + self.cdf[lo..hi].partition_point(|&c| c <= u);
        i.saturating_sub(1).min(n - 1)
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
        let i = self.cell(u);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 { (u - self.cdf[i]) / width } else { 0.5 };
        let x = ((i as f64 + du.clamp(0.0, 1.0)) / self.func.len() as f64).min(1.0 - 1e-16);
        (x, self.func[i] / self.integral, i)
    }

    /// Density at `x ∈ [0, 1)`.
    pub fn pdf(&self, x: f64) -> f64 {
        let i = ((x * self.func.len() as f64) as usize).min(self.func.len() - 1);
        self.func[i] / self.integral
    }
}

/// A piecewise-constant density on `[0, 1)²`: a marginal over rows and a conditional per row.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// From `width × height` weights, rows top to bottom.
    pub fn new(weights: &[f64], width: usize, height: usize) -> Self {
        let rows: Vec<Distribution1D> =
            (0..height).map(|y| Distribution1D::new(&weights[y * width..(y + 1) * width])).collect();
        let marginal = Distribution1D::new(&rows.iter().map(|r| r.integral()).collect::<Vec<_>>());
        Self { rows, marginal }
    }

    /// A point `(x, y)` and its density.
    pub fn sample(&self, u: Vec2) -> (Vec2, f64) {
        let (y, pdf_y, row) = self.marginal.sample_continuous(u.y);
        let (x, pdf_x, _) = self.rows[row].sample_continuous(u.x);
        (Vec2::new(x, y), pdf_x * pdf_y)
    }

    /// Density at `p`.
    pub fn pdf(&self, p: Vec2) -> f64 {
        let row = ((p.y * self.rows.len() as f64) as usize).min(self.rows.len() - 1);
        self.marginal.pdf(p.y) * self.rows[row].pdf(p.x)
    }
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
            us.extend(d.cdf.iter().copied().chain((0..=d.len()).map(|j| d.edge(j))));
            us.extend([0.0, 1.0, 1.0 - 1e-16, f64::NAN, f64::INFINITY, -0.0]);
            for u in us {
                let whole = d.cdf.partition_point(|&c| c <= u).saturating_sub(1).min(d.len() - 1);
                proptest::prop_assert_eq!(d.cell(u), whole, "u = {}", u);
            }
        }
    }

    #[test]
    fn two_dimensional_density_integrates_to_one() {
        let w: Vec<f64> = (0..12).map(|i| (i % 5) as f64).collect();
        let d = Distribution2D::new(&w, 4, 3);
        let mut sum = 0.0;
        for y in 0..30 {
            for x in 0..40 {
                sum += d.pdf(Vec2::new((x as f64 + 0.5) / 40.0, (y as f64 + 0.5) / 30.0));
            }
        }
        assert!((sum / 1200.0 - 1.0).abs() < 1e-9);
        let (p, pdf) = d.sample(Vec2::new(0.3, 0.7));
        assert!((d.pdf(p) - pdf).abs() < 1e-9);
    }
}
