//! Tensor-product patches (course, §"Tensor product Bézier and B-spline patches", §"Rational
//! Bézier and B-spline patches"): points by evaluating curves of curves (de Casteljau or de
//! Boor along the rows, then along the column, reading only the rows whose basis functions do
//! not vanish), first partial derivatives from the curves' hodographs, knot insertion per
//! direction, and the normal of a rational patch as the 4D vector product `N = P ∧ P_v ∧ P_u`
//! of the homogeneous point and its derivatives.
//!
//! The control net is stored row-major: `points[i * cols + j]` is `p_ij`, `i` along `u`.

use crate::bezier::{ControlPoint, de_casteljau};
use crate::bspline::{BSpline, SplineError, de_boor, hodograph, span};
use alhazen_math::{Mat3, Vec3, Vec4};

/// A control net of `rows × cols` points.
#[derive(Clone, Debug, PartialEq)]
pub struct Net<P> {
    /// Number of points along `u`.
    pub rows: usize,
    /// Number of points along `v`.
    pub cols: usize,
    /// Row-major points.
    pub points: Vec<P>,
}

impl<P: ControlPoint> Net<P> {
    /// A net; `None` when the sizes disagree or it is empty.
    pub fn new(rows: usize, cols: usize, points: Vec<P>) -> Option<Self> {
        (rows > 0 && cols > 0 && points.len() == rows * cols).then_some(Self { rows, cols, points })
    }

    fn row(&self, i: usize) -> Vec<P> {
        self.points[i * self.cols..(i + 1) * self.cols].to_vec()
    }
}

/// A Bézier patch of degree `(rows − 1, cols − 1)` on `[0, 1]²`.
#[derive(Clone, Debug, PartialEq)]
pub struct BezierPatch<P> {
    /// The control net.
    pub net: Net<P>,
}

impl<P: ControlPoint> BezierPatch<P> {
    /// `(p, ∂p/∂u, ∂p/∂v)` at `(u, v)`: de Casteljau along every row at `v` gives the points
    /// `q_i` of a Bézier curve in `u` (the derivative along a degree-0 direction is zero).
    pub fn partials(&self, u: f64, v: f64) -> (P, P, P) {
        let (rows, cols) = (self.net.rows, self.net.cols);
        let zero = self.net.points[0] * 0.0;
        let hodograph = |points: &[P], out: &mut Vec<P>| {
            out.clear();
            out.extend(points.windows(2).map(|w| (w[1] - w[0]) * (points.len() - 1) as f64));
        };
        let (mut q, mut qv, mut scratch) = (Vec::with_capacity(rows), Vec::with_capacity(rows), Vec::new());
        for row in self.net.points.chunks_exact(cols) {
            scratch.clear();
            scratch.extend_from_slice(row);
            q.push(de_casteljau(&mut scratch, v));
            qv.push(if cols > 1 {
                hodograph(row, &mut scratch);
                de_casteljau(&mut scratch, v)
            } else {
                zero
            });
        }
        let du = if rows > 1 {
            hodograph(&q, &mut scratch);
            de_casteljau(&mut scratch, u)
        } else {
            zero
        };
        (de_casteljau(&mut q, u), du, de_casteljau(&mut qv, u))
    }

    /// `p(u, v)` (the first of [`Self::partials`], without the derivatives).
    pub fn eval(&self, u: f64, v: f64) -> P {
        let mut scratch = Vec::with_capacity(self.net.cols);
        let mut q: Vec<P> = self
            .net
            .points
            .chunks_exact(self.net.cols)
            .map(|row| {
                scratch.clear();
                scratch.extend_from_slice(row);
                de_casteljau(&mut scratch, v)
            })
            .collect();
        de_casteljau(&mut q, u)
    }

    /// `∂p/∂u` (zero for degree 0 in `u`).
    pub fn du(&self, u: f64, v: f64) -> P {
        self.partials(u, v).1
    }

    /// `∂p/∂v`.
    pub fn dv(&self, u: f64, v: f64) -> P {
        self.partials(u, v).2
    }
}

/// A B-spline patch of degree `(n, m)` on knots `u_0…u_N`, `v_0…v_M`.
#[derive(Clone, Debug, PartialEq)]
pub struct BSplinePatch<P> {
    /// Degree along `u`.
    pub n: usize,
    /// Degree along `v`.
    pub m: usize,
    /// Knots along `u`.
    pub u_knots: Vec<f64>,
    /// Knots along `v`.
    pub v_knots: Vec<f64>,
    /// The control net (`rows = N − n`, `cols = M − m`).
    pub net: Net<P>,
}

impl<P: ControlPoint> BSplinePatch<P> {
    /// Checks the counting rule in both directions.
    pub fn new(n: usize, m: usize, u_knots: Vec<f64>, v_knots: Vec<f64>, net: Net<P>) -> Result<Self, SplineError> {
        BSpline::new(n, u_knots.clone(), vec![net.points[0]; net.rows])?;
        BSpline::new(m, v_knots.clone(), vec![net.points[0]; net.cols])?;
        Ok(Self { n, m, u_knots, v_knots, net })
    }

    fn row_curve(&self, i: usize) -> BSpline<P> {
        BSpline::new(self.m, self.v_knots.clone(), self.net.row(i)).expect("checked in new")
    }

    /// The parameter domain `([u_n, u_{N−n}], [v_m, v_{M−m}])`.
    pub fn domain(&self) -> ((f64, f64), (f64, f64)) {
        let (u, v) = (&self.u_knots, &self.v_knots);
        ((u[self.n], u[u.len() - 1 - self.n]), (v[self.m], v[v.len() - 1 - self.m]))
    }

    /// `(s, ∂s/∂u, ∂s/∂v)` at `(u, v)` (clamped to the domain): de Boor along the rows at `v`
    /// gives the points `q_i` of a B-spline in `u`; only the rows its spans at `u` read (for
    /// the point and for the hodograph) are evaluated.
    pub fn partials(&self, u: f64, v: f64) -> (P, P, P) {
        let (n, m, cols) = (self.n, self.m, self.net.cols);
        let (uk, vk) = (&self.u_knots[..], &self.v_knots[..]);
        let (uk1, vk1) = (&uk[1..uk.len() - 1], &vk[1..vk.len() - 1]);
        let zero = self.net.points[0] * 0.0;
        let uc = u.clamp(uk[n], uk[uk.len() - 1 - n]);
        let k = span(uk, n, uc);
        let (lo, hi) = if n > 0 {
            let kd = span(uk1, n - 1, uc);
            ((k - n).min(kd + 1 - n), k.max(kd + 1))
        } else {
            (k, k)
        };
        // Only rows lo..=hi matter: a sub-spline on the knots u_lo … u_{hi+n+1} has the same span.
        let sub = &uk[lo..=hi + n + 1];
        let (mut q, mut qv) = (Vec::with_capacity(hi + 1 - lo), Vec::with_capacity(hi + 1 - lo));
        let (mut scratch, mut hod) = (Vec::new(), Vec::new());
        for i in lo..=hi {
            let row = &self.net.points[i * cols..(i + 1) * cols];
            q.push(de_boor(vk, m, row, v, &mut scratch));
            qv.push(if m > 0 {
                hodograph(vk, m, row, &mut hod);
                de_boor(vk1, m - 1, &hod, v, &mut scratch)
            } else {
                zero
            });
        }
        let du = if n > 0 {
            hodograph(sub, n, &q, &mut hod);
            de_boor(&sub[1..sub.len() - 1], n - 1, &hod, uc, &mut scratch)
        } else {
            zero
        };
        (de_boor(sub, n, &q, uc, &mut scratch), du, de_boor(sub, n, &qv, uc, &mut scratch))
    }

    /// `s(u, v)` (the first of [`Self::partials`], without the derivatives).
    pub fn eval(&self, u: f64, v: f64) -> P {
        let (n, uk) = (self.n, &self.u_knots[..]);
        let uc = u.clamp(uk[n], uk[uk.len() - 1 - n]);
        let k = span(uk, n, uc);
        let mut scratch = Vec::new();
        let q: Vec<P> = (k - n..=k)
            .map(|i| {
                de_boor(
                    &self.v_knots,
                    self.m,
                    &self.net.points[i * self.net.cols..(i + 1) * self.net.cols],
                    v,
                    &mut scratch,
                )
            })
            .collect();
        de_boor(&uk[k - n..=k + n + 1], n, &q, uc, &mut scratch)
    }

    /// `∂s/∂u`.
    pub fn du(&self, u: f64, v: f64) -> P {
        self.partials(u, v).1
    }

    /// `∂s/∂v`.
    pub fn dv(&self, u: f64, v: f64) -> P {
        self.partials(u, v).2
    }

    /// Boehm's insertion of `t` into the `v` knots of every row.
    pub fn insert_v_knot(&self, t: f64) -> BSplinePatch<P> {
        let rows: Vec<BSpline<P>> = (0..self.net.rows).map(|i| self.row_curve(i).insert_knot(t)).collect();
        let cols = rows[0].points().len();
        let points = rows.iter().flat_map(|r| r.points().to_vec()).collect();
        BSplinePatch {
            v_knots: rows[0].knots().to_vec(),
            net: Net { rows: self.net.rows, cols, points },
            ..self.clone()
        }
    }

    /// Boehm's insertion of `t` into the `u` knots of every column.
    pub fn insert_u_knot(&self, t: f64) -> BSplinePatch<P> {
        let columns: Vec<BSpline<P>> = (0..self.net.cols)
            .map(|j| {
                let col = (0..self.net.rows).map(|i| self.net.points[i * self.net.cols + j]).collect();
                BSpline::new(self.n, self.u_knots.clone(), col).expect("checked in new").insert_knot(t)
            })
            .collect();
        let rows = columns[0].points().len();
        let points = (0..rows).flat_map(|i| columns.iter().map(move |c| c.points()[i])).collect();
        BSplinePatch {
            u_knots: columns[0].knots().to_vec(),
            net: Net { rows, cols: self.net.cols, points },
            ..self.clone()
        }
    }
}

/// One Lane–Riesenfeld refinement of a uniform B-spline patch of degree `(n, n)` on a regular
/// net (course, §"Mesh methods"): double rows and columns, then average each 2×2 block `n`
/// times. The result is the control net on knots twice as dense.
pub fn lane_riesenfeld_net<P: ControlPoint>(net: &Net<P>, n: usize) -> Net<P> {
    let (mut rows, mut cols) = (net.rows * 2, net.cols * 2);
    let mut d: Vec<P> = (0..rows)
        .flat_map(|i| (0..cols).map(move |j| (i / 2, j / 2)))
        .map(|(i, j)| net.points[i * net.cols + j])
        .collect();
    for _ in 0..n {
        let (r2, c2) = (rows - 1, cols - 1);
        d = (0..r2)
            .flat_map(|i| (0..c2).map(move |j| (i, j)))
            .map(|(i, j)| {
                (d[i * cols + j] + d[i * cols + j + 1] + d[(i + 1) * cols + j] + d[(i + 1) * cols + j + 1]) * 0.25
            })
            .collect();
        (rows, cols) = (r2, c2);
    }
    Net { rows, cols, points: d }
}

/// The vector product of three vectors of R⁴: the `N` with `N·x = det[x; a; b; c]`, so `N` is
/// orthogonal to `a`, `b` and `c`.
pub fn wedge4(a: Vec4, b: Vec4, c: Vec4) -> Vec4 {
    let minor = |skip: usize| {
        let pick = |v: Vec4| {
            let all = v.to_array();
            let kept: Vec<f64> = (0..4).filter(|&k| k != skip).map(|k| all[k]).collect();
            Vec3::new(kept[0], kept[1], kept[2])
        };
        Mat3::from_cols(pick(a), pick(b), pick(c)).determinant()
    };
    Vec4::new(minor(0), -minor(1), minor(2), -minor(3))
}

/// The unit normal of a rational patch from its homogeneous point and derivatives (course:
/// `N = P ∧ P_v ∧ P_u`, first three coordinates).
pub fn rational_normal(p: Vec4, pu: Vec4, pv: Vec4) -> Option<Vec3> {
    wedge4(p, pv, pu).truncate().try_normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bezier::{Bezier, bernstein};
    use proptest::prelude::*;

    fn arb_net(rows: usize, cols: usize) -> impl Strategy<Value = Net<Vec3>> {
        prop::collection::vec((-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64), rows * cols).prop_map(move |v| {
            Net::new(rows, cols, v.into_iter().map(|(x, y, z)| Vec3::new(x, y, z)).collect()).unwrap()
        })
    }

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        (a - b).length() <= tol * (1.0 + a.length())
    }

    proptest! {
        #[test]
        fn bezier_patch_is_the_double_sum(net in arb_net(3, 4), u in 0.0..1.0f64, v in 0.0..1.0f64) {
            let p = BezierPatch { net: net.clone() };
            let mut sum = Vec3::ZERO;
            for i in 0..3 {
                for j in 0..4 {
                    sum += net.points[i * 4 + j] * (bernstein(2, i, u) * bernstein(3, j, v));
                }
            }
            prop_assert!(close(p.eval(u, v), sum, 1e-12));
            let h = 1e-6;
            let fu = (p.eval(u + h, v) - p.eval(u - h, v)) / (2.0 * h);
            let fv = (p.eval(u, v + h) - p.eval(u, v - h)) / (2.0 * h);
            prop_assert!(close(p.du(u, v), fu, 1e-6) && close(p.dv(u, v), fv, 1e-6));
        }

        #[test]
        fn b_spline_patch_insertion_and_derivatives(net in arb_net(5, 5), u in 0.1..0.9f64, v in 0.1..0.9f64, t in 0.0..1.0f64) {
            let knots: Vec<f64> = vec![0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0, 2.0];
            let s = BSplinePatch::new(3, 3, knots.clone(), knots, net).unwrap();
            let (uu, vv) = (2.0 * u, 2.0 * v);
            let a = s.insert_u_knot(2.0 * t).insert_v_knot(2.0 * (1.0 - t));
            prop_assert!(close(a.eval(uu, vv), s.eval(uu, vv), 1e-10));
            let h = 1e-6;
            prop_assume!((uu - 1.0).abs() > 1e-3 && (vv - 1.0).abs() > 1e-3);
            let fu = (s.eval(uu + h, vv) - s.eval(uu - h, vv)) / (2.0 * h);
            let fv = (s.eval(uu, vv + h) - s.eval(uu, vv - h)) / (2.0 * h);
            prop_assert!(close(s.du(uu, vv), fu, 1e-5) && close(s.dv(uu, vv), fv, 1e-5));
        }

        #[test]
        fn b_spline_patch_partials_are_curves_of_curves(net in arb_net(4, 6), u in 0.0..=1.0f64, v in 0.0..=1.0f64) {
            // Degrees (2, 3) on clamped, non-uniform knots with a double knot along v.
            let (uk, vk) = (vec![0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0], vec![0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 2.0, 2.0, 2.0, 2.0]);
            let s = BSplinePatch::new(2, 3, uk.clone(), vk.clone(), net.clone()).unwrap();
            let (uu, vv) = (u, 2.0 * v);
            // The course's way: de Boor along every row at v, then along the column at u.
            let rows: Vec<BSpline<Vec3>> = (0..4).map(|i| BSpline::new(3, vk.clone(), net.row(i)).unwrap()).collect();
            let column = BSpline::new(2, uk.clone(), rows.iter().map(|r| r.eval(vv)).collect()).unwrap();
            let column_v = BSpline::new(2, uk, rows.iter().map(|r| r.derivative().unwrap().eval(vv)).collect()).unwrap();
            // Bit for bit: meshes of neighbouring patches are welded by exact positions.
            let (p, pu, pv) = s.partials(uu, vv);
            prop_assert_eq!(p, column.eval(uu));
            prop_assert_eq!(s.eval(uu, vv), p);
            prop_assert_eq!(pu, column.derivative().unwrap().eval(uu));
            prop_assert_eq!(pv, column_v.eval(uu));
            prop_assert_eq!(s.domain(), ((0.0, 1.0), (0.0, 2.0)));
        }

        #[test]
        fn bezier_patch_partials_are_curves_of_curves(net in arb_net(4, 3), u in -0.1..1.1f64, v in -0.1..1.1f64) {
            let p = BezierPatch { net: net.clone() };
            let rows: Vec<Bezier<Vec3>> = (0..4).map(|i| Bezier::new(net.row(i)).unwrap()).collect();
            let column = Bezier::new(rows.iter().map(|r| r.eval(v)).collect()).unwrap();
            let column_v = Bezier::new(rows.iter().map(|r| r.derivative().unwrap().eval(v)).collect()).unwrap();
            let (s, su, sv) = p.partials(u, v);
            prop_assert_eq!(s, column.eval(u));
            prop_assert_eq!(p.eval(u, v), s);
            prop_assert_eq!(su, column.derivative().unwrap().eval(u));
            prop_assert_eq!(sv, column_v.eval(u));
        }

        #[test]
        fn bezier_patches_sharing_an_edge_agree_bit_for_bit(a in arb_net(4, 4), b in arb_net(3, 4), j in 0..=16u32) {
            // `b` starts with the last row of `a`, once as it is and once reversed along v; at the
            // tessellator's dyadic parameters the shared edge must give the same bits.
            let t = j as f64 / 16.0;
            let edge = a.row(3);
            let mut same = b.points.clone();
            same[..4].copy_from_slice(&edge);
            let mut reversed = same.clone();
            reversed[..4].reverse();
            let (a, same, reversed) = (BezierPatch { net: a }, Net::new(3, 4, same).unwrap(), Net::new(3, 4, reversed).unwrap());
            prop_assert_eq!(a.eval(1.0, t), BezierPatch { net: same }.eval(0.0, t));
            prop_assert_eq!(a.eval(1.0, t), BezierPatch { net: reversed }.eval(0.0, 1.0 - t));
        }

        #[test]
        fn rational_normal_is_the_normal_of_the_projected_patch(net in arb_net(3, 3), w in prop::collection::vec(0.3..3.0f64, 9), u in 0.05..0.95f64, v in 0.05..0.95f64) {
            let hom = Net::new(3, 3, net.points.iter().zip(&w).map(|(p, w)| (*p * *w).extend(*w)).collect()).unwrap();
            let p = BezierPatch { net: hom };
            let n = rational_normal(p.eval(u, v), p.du(u, v), p.dv(u, v));
            // Cartesian derivatives by finite differences of the projected patch.
            let proj = |u: f64, v: f64| { let h = p.eval(u, v); h.truncate() / h.w };
            let h = 1e-6;
            let cu = (proj(u + h, v) - proj(u - h, v)) / (2.0 * h);
            let cv = (proj(u, v + h) - proj(u, v - h)) / (2.0 * h);
            if let (Some(n), Some(c)) = (n, cu.cross(cv).try_normalize()) {
                prop_assume!(cu.length() > 1e-3 && cv.length() > 1e-3 && cu.cross(cv).length() > 1e-3 * cu.length() * cv.length());
                prop_assert!(n.cross(c).length() < 1e-5, "{n} vs {c}");
            }
        }
    }

    #[test]
    fn lane_riesenfeld_net_converges_to_the_uniform_bicubic_patch() {
        let pts: Vec<Vec3> =
            (0..36).map(|k| Vec3::new((k / 6) as f64, (k % 6) as f64, ((k * 7919) % 11) as f64 * 0.1)).collect();
        let net = Net::new(6, 6, pts).unwrap();
        let knots: Vec<f64> = (0..10).map(|i| i as f64).collect();
        let s = BSplinePatch::new(3, 3, knots.clone(), knots, net.clone()).unwrap();
        let mut refined = net;
        let mut errors = vec![];
        for _ in 0..4 {
            refined = lane_riesenfeld_net(&refined, 3);
            let err = (0..=10)
                .flat_map(|i| (0..=10).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let p = s.eval(3.0 + 3.0 * i as f64 / 10.0, 3.0 + 3.0 * j as f64 / 10.0);
                    refined.points.iter().map(|q| (*q - p).length()).fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max);
            errors.push(err);
        }
        assert!(errors.windows(2).all(|w| w[1] < 0.7 * w[0]), "{errors:?}");
    }

    #[test]
    fn wedge4_is_orthogonal_to_its_factors() {
        let (a, b, c) = (Vec4::new(1.0, 2.0, 0.5, 1.0), Vec4::new(-0.3, 1.0, 2.0, 0.2), Vec4::new(0.7, -1.0, 0.1, 3.0));
        let n = wedge4(a, b, c);
        for x in [a, b, c] {
            assert!(n.dot(x).abs() < 1e-12);
        }
        let x = Vec4::new(0.2, 0.3, -0.4, 0.5);
        let det = alhazen_math::Mat4::from_cols(x, a, b, c).transpose().determinant();
        assert!((n.dot(x) - det).abs() < 1e-12);
    }
}
