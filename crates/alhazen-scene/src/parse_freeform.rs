//! The scene format's free-form shapes (course, §"B-spline curves", §"Rational Bézier and
//! B-spline patches", §"Some constructions of surfaces"): Bézier and B-spline patches, NURBS
//! curves with knots and weights (drawn as tubes), swept surfaces with computed or given
//! auxiliary guides and any section (by default the exact rational circle), surfaces of
//! revolution of NURBS profiles, and lofts through curves of any degrees and knots. Every surface
//! is tessellated to its `tolerance`, within the memory budget.

use crate::parse::Parser;
use crate::reader::{Node, R, Table};
use alhazen_geom::TriangleMesh;
use alhazen_geom::bspline::{BSpline, nurbs_circle, weighted};
use alhazen_geom::construct::{self, FramedSweep};
use alhazen_geom::tessellate::{Surface, grid_for, tessellate_grid};
use alhazen_math::{Vec3, Vec4};

/// The chordal tolerance when a shape gives none (scene units).
const DEFAULT_TOLERANCE: f64 = 1e-3;
/// Bytes a tessellated grid vertex and its two triangles take.
const BYTES_PER_GRID_VERTEX: u64 = 24 + 24 + 16 + 2 * 12;

/// What a plain list of points means where a curve is expected.
#[derive(Clone, Copy, PartialEq)]
enum PointList {
    /// The cubic B-spline interpolating them at chord-length parameters.
    Through,
    /// The control points of a clamped uniform B-spline (cubic, or lower for fewer points).
    Control,
}

/// Whether a curve's points are `[x, y, z]` or planar `[a, b]` (profiles and sections).
#[derive(Clone, Copy, PartialEq)]
enum Dim {
    Three,
    Two,
}

impl Parser<'_> {
    /// `shape = "patch"`: a (rational) Bézier patch — or, with `degree = [n, m]`, `knots_u` and
    /// `knots_v`, a (rational) B-spline patch — control points row-major, tessellated to the chordal
    /// `tolerance`.
    pub(crate) fn patch(&mut self, t: &Table) -> R<TriangleMesh> {
        use alhazen_geom::patch::{BSplinePatch, BezierPatch, Net};
        let pts_node = t.req("points")?;
        let points: Vec<Vec3> = pts_node.array()?.iter().map(|p| p.vec3()).collect::<R<_>>()?;
        let rows = t.req("rows")?.integer(1, 256)? as usize;
        if points.len() < 2 * rows || !points.len().is_multiple_of(rows) {
            return Err(pts_node.err(format!("{} points do not form {rows} rows of at least 2", points.len())));
        }
        let cols = points.len() / rows;
        let tol = t.get("tolerance").map_or(Ok(1e-3), |n| n.positive())?;
        let weights: Option<Vec<f64>> = match t.get("weights") {
            None => None,
            Some(w) => {
                let ws: Vec<f64> = w.array()?.iter().map(|x| x.positive()).collect::<R<_>>()?;
                if ws.len() != points.len() {
                    return Err(w.err(format!("{} weights for {} points", ws.len(), points.len())));
                }
                Some(ws)
            }
        };
        let knots = |key: &str| -> R<Option<Vec<f64>>> {
            t.get(key).map(|k| k.array()?.iter().map(|x| x.f64()).collect::<R<Vec<f64>>>()).transpose()
        };
        let spline = match (t.get("degree"), knots("knots_u")?, knots("knots_v")?) {
            (None, None, None) => None,
            (Some(d), Some(ku), Some(kv)) => {
                let [n, m] = d.numbers::<2>()?;
                if n < 1.0 || m < 1.0 || n.fract() != 0.0 || m.fract() != 0.0 || n > 10.0 || m > 10.0 {
                    return Err(d.err("`degree`: expected two integers from 1 to 10"));
                }
                Some((n as usize, m as usize, ku, kv, d))
            }
            _ => return Err(pts_node.err("a B-spline patch needs all of `degree`, `knots_u` and `knots_v`")),
        };
        // Rational patches live in homogeneous coordinates (w p, w).
        let homogeneous =
            weights.map(|ws| points.iter().zip(&ws).map(|(p, w)| (*p * *w).extend(*w)).collect::<Vec<_>>());
        match (spline, homogeneous) {
            (None, None) => {
                self.tessellated(t, &BezierPatch { net: Net::new(rows, cols, points).expect("sizes checked") }, tol)
            }
            (None, Some(hom)) => {
                self.tessellated(t, &BezierPatch { net: Net::new(rows, cols, hom).expect("sizes checked") }, tol)
            }
            (Some((n, m, ku, kv, d)), hom) => {
                let bad = |e: alhazen_geom::bspline::SplineError| d.err(format!("B-spline patch: {e}"));
                match hom {
                    None => self.tessellated(
                        t,
                        &BSplinePatch::new(n, m, ku, kv, Net::new(rows, cols, points).expect("sizes checked"))
                            .map_err(bad)?,
                        tol,
                    ),
                    Some(hom) => self.tessellated(
                        t,
                        &BSplinePatch::new(n, m, ku, kv, Net::new(rows, cols, hom).expect("sizes checked"))
                            .map_err(bad)?,
                        tol,
                    ),
                }
            }
        }
    }

    /// `shape = "curve"`: a Bézier curve (`kind = "bezier"`, the default), a clamped uniform
    /// B-spline (`kind = "bspline"`, `degree`) or a NURBS curve (`kind = "nurbs"`, or any of
    /// `knots` and `weights`), drawn as a tube of `radius` with an exact circular section.
    pub(crate) fn curve(&mut self, t: &Table) -> R<TriangleMesh> {
        let nurbs_keys = t.get("knots").is_some() || t.get("weights").is_some();
        let kind = match t.get("kind") {
            Some(k) => k.choice(&["bezier", "bspline", "nurbs"])?,
            None if nurbs_keys => "nurbs",
            None => "bezier",
        };
        let curve = if kind == "bezier" {
            if nurbs_keys {
                let key = if t.get("knots").is_some() { "knots" } else { "weights" };
                return Err(t.req(key)?.err(format!("a Bézier curve has no `{key}`: use kind = \"nurbs\"")));
            }
            let points = points_of(&t.req("points")?, Dim::Three)?;
            let n = points.len() - 1;
            let knots = [vec![0.0; n + 1], vec![1.0; n + 1]].concat();
            BSpline::new(n, knots, points.iter().map(|p| p.extend(1.0)).collect())
                .expect("n + 1 points on 2n + 2 knots")
        } else {
            nurbs_from(t, Dim::Three)?
        };
        let radius = t.get("radius").map_or(Ok(0.02), |n| n.positive())?;
        let tol = tolerance(t)?;
        let tube = construct::swept_tube(&curve, radius, tol).ok_or_else(|| {
            t.req("points").expect("read").err("the curve has no tangent anywhere: its control points coincide")
        })?;
        self.check_sweep(t, &tube, tol);
        self.tessellated(t, &tube.surface, tol)
    }

    /// `shape = "sweep"`: the course's swept surface. `guide` is a curve (points it passes
    /// through, or a NURBS table); the section is the exact circle of `radius`, or `section`, a
    /// planar curve in the `(normal, binormal)` plane. The auxiliary guides are a
    /// rotation-minimising frame refined to `tolerance`, or the three curves of `guides`
    /// (made compatible with the guide by degree elevation and knot insertion).
    pub(crate) fn sweep(&mut self, t: &Table) -> R<TriangleMesh> {
        let guide_node = t.req("guide")?;
        let guide = curve_of(&guide_node, PointList::Through, Dim::Three)?;
        let section = match (t.get("section"), t.get("radius")) {
            (Some(s), None) => curve_of(&s, PointList::Control, Dim::Two)?,
            (None, r) => nurbs_circle(Vec3::ZERO, r.map_or(Ok(0.1), |n| n.positive())?),
            (Some(_), Some(r)) => {
                return Err(r.err("`radius` and `section` exclude each other: a section has its own size"));
            }
        };
        let tol = tolerance(t)?;
        let surface = match t.get("guides") {
            None => {
                let swept = construct::framed_sweep(&guide, &section, tol)
                    .ok_or_else(|| guide_node.err("the guide has no tangent anywhere: its points coincide"))?;
                self.check_sweep(t, &swept, tol);
                swept.surface
            }
            Some(g) => {
                let items = g.array()?;
                if items.len() != 3 {
                    return Err(g.err(format!(
                        "`guides`: expected the three auxiliary guides x1, x2, x3, found {}",
                        items.len()
                    )));
                }
                let mut curves = vec![guide];
                for item in &items {
                    curves.push(curve_of(item, PointList::Control, Dim::Three)?);
                }
                let curves = alhazen_geom::bspline::make_compatible(&curves);
                let vectors: Vec<BSpline<Vec3>> = curves[1..]
                    .iter()
                    .map(|c| {
                        BSpline::new(
                            c.degree(),
                            c.knots().to_vec(),
                            c.points().iter().map(|h| h.truncate() / h.w).collect(),
                        )
                        .expect("compatible")
                    })
                    .collect();
                construct::sweep(&curves[0], [&vectors[0], &vectors[1], &vectors[2]], &section)
                    .expect("made compatible")
            }
        };
        self.tessellated(t, &surface, tol)
    }

    /// `shape = "revolution"`: the surface of revolution about the `y` axis of `profile`, points
    /// `[radius, height]` it passes through or a NURBS table of them, by the spherical product
    /// with the exact NURBS circle.
    pub(crate) fn revolution(&mut self, t: &Table) -> R<TriangleMesh> {
        let node = t.req("profile")?;
        let profile = curve_of(&node, PointList::Through, Dim::Two)?;
        // Points the profile passes through, or control points (the curve lies in their hull).
        let given = if node.is_table() { node.table_any()?.req("points")? } else { node.clone() };
        for p in given.array()? {
            if p.numbers::<2>()?[0] < 0.0 {
                return Err(p.err("a profile point's radius (its distance from the axis) cannot be negative"));
            }
        }
        let tol = tolerance(t)?;
        let surface = construct::revolution_of(&profile).expect("a profile is a valid curve");
        let mut mesh = self.tessellated(t, &surface, tol)?;
        // The construction revolves about z; scenes are y-up: rotate by −90° about x.
        for p in mesh.positions.iter_mut().chain(mesh.normals.iter_mut()) {
            *p = Vec3::new(p.x, p.z, -p.y);
        }
        Ok(mesh)
    }

    /// `shape = "loft"`: the surface through `curves` (each a list of control points of a clamped
    /// uniform B-spline or a NURBS table; degrees and knots may differ), interpolated across by
    /// chord length between their control points' centroids.
    pub(crate) fn loft(&mut self, t: &Table) -> R<TriangleMesh> {
        let node = t.req("curves")?;
        let items = node.array()?;
        if items.len() < 2 {
            return Err(node.err("`curves`: expected at least 2 curves"));
        }
        let curves: Vec<BSpline<Vec4>> =
            items.iter().map(|c| curve_of(c, PointList::Control, Dim::Three)).collect::<R<_>>()?;
        let centroids: Vec<Vec3> = curves
            .iter()
            .map(|c| c.points().iter().map(|h| h.truncate() / h.w).sum::<Vec3>() / c.points().len() as f64)
            .collect();
        if let Some(k) = centroids.windows(2).position(|w| (w[1] - w[0]).length() == 0.0) {
            return Err(items[k + 1].err(format!(
                "curves {} and {} have the same centroid: no parameter between them",
                k + 1,
                k + 2
            )));
        }
        let params = construct::chord_lengths(&centroids);
        let surface = construct::loft(&curves, &params).ok_or_else(|| node.err("the curves cannot be lofted"))?;
        self.tessellated(t, &surface, tolerance(t)?)
    }

    /// A warning when a sweep's frame stopped short of `tolerance`.
    fn check_sweep(&mut self, t: &Table, swept: &FramedSweep, tol: f64) {
        if swept.error > tol {
            let name = shape_name(t, "a swept shape");
            self.warnings.push(format!(
                "{name}: the sweep's frame is within {:.2e} of its guide's normal planes, not the `tolerance` {tol:.2e} (the guide was subdivided {} times, to {} control points)",
                swept.error,
                swept.subdivisions,
                swept.surface.net.rows
            ));
        }
    }

    /// `surface` tessellated to `tol`, refused (at the shape) if the grid would not fit in the
    /// memory budget.
    fn tessellated<S: Surface>(&mut self, t: &Table, surface: &S, tol: f64) -> R<TriangleMesh> {
        let grid = grid_for(surface, tol);
        let ((ku, kv), error) = (grid.cells(), grid.error);
        let needed = ((ku + 1) * (kv + 1)) as u64 * BYTES_PER_GRID_VERTEX;
        if needed > self.memory_budget {
            let at = t.get("tolerance").unwrap_or(t.req("shape")?);
            return Err(at.err(format!(
                "tessellating this surface to the tolerance {tol} takes a {ku} × {kv} grid, about {}, more than the memory budget of {} (raise `tolerance`, or the budget: alhazen --max-memory)",
                crate::format_bytes(needed),
                crate::format_bytes(self.memory_budget)
            )));
        }
        if error > tol {
            let name = shape_name(t, "a free-form surface");
            self.warnings.push(format!(
                "{name}: tessellated within {error:.2e}, not the `tolerance` {tol:.2e} ({} cells a side at most)",
                alhazen_geom::tessellate::MAX_CELLS_PER_SIDE
            ));
        }
        Ok(tessellate_grid(surface, &grid))
    }
}

/// A shape's `name` for messages, or `otherwise`.
fn shape_name(t: &Table, otherwise: &str) -> String {
    t.get("name").and_then(|n| n.str().ok().map(str::to_string)).unwrap_or_else(|| otherwise.into())
}

/// A shape's `tolerance` (chordal, in scene units).
fn tolerance(t: &Table) -> R<f64> {
    t.get("tolerance").map_or(Ok(DEFAULT_TOLERANCE), |n| n.positive())
}

/// Points `[x, y, z]` or `[a, b]` (as `(a, b, 0)`), at least 2.
fn points_of(n: &Node, dim: Dim) -> R<Vec<Vec3>> {
    let items = n.array()?;
    let points: Vec<Vec3> = items
        .iter()
        .map(|p| match dim {
            Dim::Three => p.vec3(),
            Dim::Two => p.numbers::<2>().map(|[a, b]| Vec3::new(a, b, 0.0)),
        })
        .collect::<R<_>>()?;
    if points.len() < 2 {
        return Err(n.err(format!(
            "`{}`: a curve needs at least 2 points — at least 2 control points, or 2 points to pass through — found {}",
            n.key,
            points.len()
        )));
    }
    Ok(points)
}

/// A curve where one is expected: a list of points (meaning `list`) or a NURBS table
/// `{ degree, points, weights, knots }`, as homogeneous control points.
fn curve_of(n: &Node, list: PointList, dim: Dim) -> R<BSpline<Vec4>> {
    if n.is_table() {
        return nurbs_from(&n.table(&["degree", "points", "weights", "knots"])?, dim);
    }
    let points = points_of(n, dim)?;
    let items = n.array()?;
    if let Some(k) = points.windows(2).position(|w| w[0] == w[1]).filter(|_| list == PointList::Through) {
        return Err(items[k + 1].err(format!("{} points {} and {} coincide", n.key, k + 1, k + 2)));
    }
    let curve = match list {
        PointList::Through => construct::interpolate_cubic(&points, &construct::chord_lengths(&points)),
        PointList::Control => BSpline::clamped_uniform((points.len() - 1).min(3), points).ok(),
    }
    .ok_or_else(|| n.err("these points do not define a curve"))?;
    Ok(BSpline::new(curve.degree(), curve.knots().to_vec(), curve.points().iter().map(|p| p.extend(1.0)).collect())
        .expect("same knots"))
}

/// The NURBS curve of a table with `points`, optional `degree` (default cubic, or lower for
/// fewer points), `weights` (default 1) and `knots` (default clamped uniform).
fn nurbs_from(t: &Table, dim: Dim) -> R<BSpline<Vec4>> {
    let points_node = t.req("points")?;
    let points = points_of(&points_node, dim)?;
    let degree = match t.get("degree") {
        Some(d) => {
            let n = d.integer(1, 10)? as usize;
            if n >= points.len() {
                return Err(d.err(format!(
                    "a curve of degree {n} needs at least {} control points, found {}",
                    n + 1,
                    points.len()
                )));
            }
            n
        }
        None => (points.len() - 1).min(3),
    };
    let weights: Vec<f64> = match t.get("weights") {
        None => vec![1.0; points.len()],
        Some(w) => {
            let ws: Vec<f64> = w.array()?.iter().map(|x| x.positive()).collect::<R<_>>()?;
            if ws.len() != points.len() {
                return Err(w.err(format!("{} weights for {} control points", ws.len(), points.len())));
            }
            ws
        }
    };
    let homogeneous: Vec<Vec4> = points.iter().zip(&weights).map(|(p, w)| weighted(*p, *w)).collect();
    let Some(k) = t.get("knots") else {
        return Ok(BSpline::clamped_uniform(degree, homogeneous).expect("degree below the point count"));
    };
    let knots: Vec<f64> = k.array()?.iter().map(|x| x.f64()).collect::<R<_>>()?;
    if knots.len() != points.len() + degree + 1 {
        return Err(k.err(format!(
            "a curve of degree {degree} with {} control points needs {} knots (points + degree + 1), found {}",
            points.len(),
            points.len() + degree + 1,
            knots.len()
        )));
    }
    let curve = BSpline::new(degree, knots, homogeneous).map_err(|e| k.err(format!("`knots`: {e}")))?;
    let (a, b) = curve.domain();
    if let Some(u) = curve
        .breakpoints()
        .into_iter()
        .filter(|u| *u > a && *u < b)
        .find(|u| curve.knots().iter().filter(|k| *k == u).count() > degree)
    {
        return Err(k.err(format!("`knots`: the inner knot {u} repeats more than {degree} times (the degree): the curve would break apart there")));
    }
    Ok(curve)
}
