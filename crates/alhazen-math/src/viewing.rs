//! The viewing pipeline of the lecture ("Viewing – from Shirley et al. Chapter 7") and the course
//! (§"The implementation of perspective projections", §"Stereoscopic vision").
//!
//! Matrices act on column vectors `[x y z 1]ᵀ`. The viewer looks down `−w` (the camera's `−z`).
//!
//! Seed typos, corrected here and pinned by the tests below:
//! * the course's parallel-projection matrix prints `2/(r−t)` and `(t+r)/(t−r)` in its first
//!   row; the map of `[l, r]` onto `[−1, 1]` needs `2/(r−l)` and `(l+r)/(l−r)` (and the inverse
//!   `(r−l)/2`, `(l+r)/2`);
//! * the lecture's pixel matrix `M_o` omits the translation `(n_x−1)/2, (n_y−1)/2` that moves
//!   the canonical square onto pixel centres; [`viewport`] includes it.

use crate::{Mat4, Vec3, Vec4};

/// The orthonormal camera frame `(u, v, w)` and eye `e` of the lecture's "Arbitrary view
/// positions": `w = −g/|g|`, `u = t×w/|t×w|`, `v = w×u`, for gaze `g` and view-up `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewFrame {
    /// Eye point `e`.
    pub eye: Vec3,
    /// Right.
    pub u: Vec3,
    /// Up.
    pub v: Vec3,
    /// Backwards (the viewer looks along `−w`).
    pub w: Vec3,
}

impl ViewFrame {
    /// The frame looking from `eye` towards `target`; `None` when they coincide or `up` is
    /// parallel to the gaze.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Option<Self> {
        let g = target - eye;
        let w = (-g).try_normalize()?;
        let u = up.cross(w).try_normalize()?;
        let v = w.cross(u);
        Some(Self { eye, u, v, w })
    }

    /// The lecture's `M_v`: move `e` to the origin and align `(u, v, w)` with `(x, y, z)`.
    pub fn world_to_view(&self) -> Mat4 {
        let r = Mat4::from_cols(
            Vec4::new(self.u.x, self.v.x, self.w.x, 0.0),
            Vec4::new(self.u.y, self.v.y, self.w.y, 0.0),
            Vec4::new(self.u.z, self.v.z, self.w.z, 0.0),
            Vec4::W,
        );
        r * Mat4::from_translation(-self.eye)
    }

    /// The inverse of [`ViewFrame::world_to_view`]: columns `u, v, w, e`.
    pub fn view_to_world(&self) -> Mat4 {
        Mat4::from_cols(self.u.extend(0.0), self.v.extend(0.0), self.w.extend(0.0), self.eye.extend(1.0))
    }

    /// A view-space direction `(x, y, z)` expressed in world space: `x u + y v + z w`.
    #[inline]
    pub fn to_world_dir(&self, d: Vec3) -> Vec3 {
        self.u * d.x + self.v * d.y + self.w * d.z
    }
}

/// A viewing volume given by `l, r, b, t` (on the near plane for a perspective frustum) and the
/// positive distances `n < f` of the near and far planes `z = −n`, `z = −f`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frustum {
    /// Left.
    pub l: f64,
    /// Right.
    pub r: f64,
    /// Bottom.
    pub b: f64,
    /// Top.
    pub t: f64,
    /// Near distance.
    pub n: f64,
    /// Far distance.
    pub f: f64,
}

impl Frustum {
    /// A symmetric perspective frustum with vertical field of view `fovy` (radians) and aspect
    /// `width / height`.
    pub fn symmetric(fovy: f64, aspect: f64, n: f64, f: f64) -> Self {
        let t = n * (fovy * 0.5).tan();
        let r = t * aspect;
        Self { l: -r, r, b: -t, t, n, f }
    }

    /// The course's perspective matrix `P` (frustum → standard cube `[−1, 1]³`).
    pub fn perspective(&self) -> Mat4 {
        let Self { l, r, b, t, n, f } = *self;
        Mat4::from_cols(
            Vec4::new(2.0 * n / (r - l), 0.0, 0.0, 0.0),
            Vec4::new(0.0, 2.0 * n / (t - b), 0.0, 0.0),
            Vec4::new((r + l) / (r - l), (t + b) / (t - b), (n + f) / (n - f), -1.0),
            Vec4::new(0.0, 0.0, 2.0 * f * n / (n - f), 0.0),
        )
    }

    /// The course's `P⁻¹` for [`Frustum::perspective`], in closed form.
    pub fn perspective_inverse(&self) -> Mat4 {
        let Self { l, r, b, t, n, f } = *self;
        Mat4::from_cols(
            Vec4::new((r - l) / (2.0 * n), 0.0, 0.0, 0.0),
            Vec4::new(0.0, (t - b) / (2.0 * n), 0.0, 0.0),
            Vec4::new(0.0, 0.0, 0.0, (n - f) / (2.0 * f * n)),
            Vec4::new((r + l) / (2.0 * n), (t + b) / (2.0 * n), -1.0, (n + f) / (2.0 * f * n)),
        )
    }

    /// The course's parallel-projection matrix (box `(l,b,−n)`–`(r,t,−f)` → standard cube), with
    /// the first-row typo corrected (see the module doc).
    pub fn orthographic(&self) -> Mat4 {
        let Self { l, r, b, t, n, f } = *self;
        Mat4::from_cols(
            Vec4::new(2.0 / (r - l), 0.0, 0.0, 0.0),
            Vec4::new(0.0, 2.0 / (t - b), 0.0, 0.0),
            Vec4::new(0.0, 0.0, 2.0 / (n - f), 0.0),
            Vec4::new((l + r) / (l - r), (b + t) / (b - t), (n + f) / (n - f), 1.0),
        )
    }

    /// The closed-form inverse of [`Frustum::orthographic`].
    pub fn orthographic_inverse(&self) -> Mat4 {
        let Self { l, r, b, t, n, f } = *self;
        Mat4::from_cols(
            Vec4::new((r - l) / 2.0, 0.0, 0.0, 0.0),
            Vec4::new(0.0, (t - b) / 2.0, 0.0, 0.0),
            Vec4::new(0.0, 0.0, (n - f) / 2.0, 0.0),
            Vec4::new((l + r) / 2.0, (b + t) / 2.0, -(n + f) / 2.0, 1.0),
        )
    }
}

/// The lecture's orthographic `M_orth` for a view volume with *signed* planes `z = n`, `z = f`
/// (`0 > n > f`): scale ∘ translate to the canonical cube.
pub fn lecture_orthographic(l: f64, r: f64, b: f64, t: f64, n: f64, f: f64) -> Mat4 {
    let scale = Mat4::from_scale(Vec3::new(2.0 / (r - l), 2.0 / (t - b), 2.0 / (n - f)));
    let shift = Mat4::from_translation(Vec3::new(-(l + r) / 2.0, -(b + t) / 2.0, -(n + f) / 2.0));
    scale * shift
}

/// The lecture's perspective matrix `M_p` (signed `n`, `f`): `[x y z 1] ↦ [nx ny (n+f)z−fn z]`.
pub fn lecture_perspective(n: f64, f: f64) -> Mat4 {
    Mat4::from_cols(
        Vec4::new(n, 0.0, 0.0, 0.0),
        Vec4::new(0.0, n, 0.0, 0.0),
        Vec4::new(0.0, 0.0, n + f, 1.0),
        Vec4::new(0.0, 0.0, -f * n, 0.0),
    )
}

/// Canonical square `[−1, 1]²` → pixel centres of an `nx × ny` image (Shirley's `M_vp`; `z`
/// passes through).
pub fn viewport(nx: f64, ny: f64) -> Mat4 {
    Mat4::from_cols(
        Vec4::new(nx / 2.0, 0.0, 0.0, 0.0),
        Vec4::new(0.0, ny / 2.0, 0.0, 0.0),
        Vec4::Z,
        Vec4::new((nx - 1.0) / 2.0, (ny - 1.0) / 2.0, 0.0, 1.0),
    )
}

/// The lecture's 2D "rectangle to rectangle" window→viewport map as a 3×3 homogeneous matrix
/// in a 4×4 (the `z` row is identity): `[xl, xr]×[yb, yt] → [ul, ur]×[vb, vt]`.
pub fn window_to_viewport(window: [f64; 4], port: [f64; 4]) -> Mat4 {
    let [xl, xr, yb, yt] = window;
    let [ul, ur, vb, vt] = port;
    let to_origin = Mat4::from_translation(Vec3::new(-xl, -yb, 0.0));
    let scale = Mat4::from_scale(Vec3::new((ur - ul) / (xr - xl), (vt - vb) / (yt - yb), 1.0));
    Mat4::from_translation(Vec3::new(ul, vb, 0.0)) * scale * to_origin
}

/// Homogenise `[hx hy hz h]` to `[x y z]`; `None` for `h = 0` (a point at infinity).
pub fn homogenize(p: Vec4) -> Option<Vec3> {
    (p.w != 0.0 && p.is_finite()).then(|| p.truncate() / p.w)
}

/// The two frusta of a stereo pair (course, §"Stereoscopic vision"): eyes `eye_distance` apart,
/// at `screen_distance` from a screen of `screen_w × screen_h`, all in viewer units. Both share
/// `b, t, n, f`; each eye sits at `∓eye_distance/2` along `u`, and the frustum is skewed so both
/// see the same screen rectangle.
pub fn stereo_frusta(
    eye_distance: f64,
    screen_distance: f64,
    screen_w: f64,
    screen_h: f64,
    n: f64,
    f: f64,
) -> (Frustum, Frustum) {
    let k = n / screen_distance;
    let half = eye_distance / 2.0;
    let (b, t) = (-screen_h / 2.0 * k, screen_h / 2.0 * k);
    // Left eye at x = −half sees the screen x ∈ [−W/2, W/2], i.e. [−W/2 + half, W/2 + half]
    // relative to itself.
    let left = Frustum { l: (-screen_w / 2.0 + half) * k, r: (screen_w / 2.0 + half) * k, b, t, n, f };
    let right = Frustum { l: (-screen_w / 2.0 - half) * k, r: (screen_w / 2.0 - half) * k, b, t, n, f };
    (left, right)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Mat4, b: Mat4, tol: f64) -> bool {
        a.to_cols_array().iter().zip(b.to_cols_array()).all(|(x, y)| (x - y).abs() <= tol)
    }

    const FR: Frustum = Frustum { l: -1.5, r: 2.0, b: -0.7, t: 1.1, n: 0.5, f: 40.0 };

    #[test]
    fn perspective_maps_frustum_corners_to_standard_cube() {
        let p = FR.perspective();
        let near_bl = homogenize(p * Vec4::new(FR.l, FR.b, -FR.n, 1.0)).unwrap();
        assert!((near_bl - Vec3::new(-1.0, -1.0, -1.0)).length() < 1e-12);
        let k = FR.f / FR.n;
        let far_tr = homogenize(p * Vec4::new(FR.r * k, FR.t * k, -FR.f, 1.0)).unwrap();
        assert!((far_tr - Vec3::ONE).length() < 1e-12);
    }

    #[test]
    fn closed_form_inverses_match_the_seed() {
        assert!(close(FR.perspective() * FR.perspective_inverse(), Mat4::IDENTITY, 1e-12));
        assert!(close(FR.perspective_inverse(), FR.perspective().inverse(), 1e-9));
        assert!(close(FR.orthographic() * FR.orthographic_inverse(), Mat4::IDENTITY, 1e-12));
    }

    #[test]
    fn seed_entries_of_p_are_as_printed() {
        let p = FR.perspective();
        let (l, r, b, t, n, f) = (FR.l, FR.r, FR.b, FR.t, FR.n, FR.f);
        assert_eq!(p.row(0), Vec4::new(2.0 * n / (r - l), 0.0, (r + l) / (r - l), 0.0));
        assert_eq!(p.row(1), Vec4::new(0.0, 2.0 * n / (t - b), (t + b) / (t - b), 0.0));
        assert_eq!(p.row(2), Vec4::new(0.0, 0.0, (n + f) / (n - f), 2.0 * f * n / (n - f)));
        assert_eq!(p.row(3), Vec4::new(0.0, 0.0, -1.0, 0.0));
        let pi = FR.perspective_inverse();
        assert_eq!(pi.row(2), Vec4::new(0.0, 0.0, 0.0, -1.0));
        assert_eq!(pi.row(3), Vec4::new(0.0, 0.0, (n - f) / (2.0 * f * n), (n + f) / (2.0 * f * n)));
    }

    #[test]
    fn orthographic_typo_corrected() {
        // The seed's 2/(r−t) would not map x = l, r to ∓1; ours does.
        let p = FR.orthographic();
        let lo = p * Vec4::new(FR.l, FR.b, -FR.n, 1.0);
        let hi = p * Vec4::new(FR.r, FR.t, -FR.f, 1.0);
        assert!((lo.truncate() - Vec3::new(-1.0, -1.0, -1.0)).length() < 1e-12);
        assert!((hi.truncate() - Vec3::ONE).length() < 1e-12);
        let seed_row0 = 2.0 / (FR.r - FR.t) * FR.l + (FR.t + FR.r) / (FR.t - FR.r);
        assert!((seed_row0 + 1.0).abs() > 0.1, "the seed's printed formula is indeed wrong");
    }

    #[test]
    fn lecture_matrices() {
        let (n, f) = (-1.0, -10.0);
        let mp = lecture_perspective(n, f);
        for z in [n, f, -3.0] {
            let q = homogenize(mp * Vec4::new(2.0, 3.0, z, 1.0)).unwrap();
            assert!((q - Vec3::new(n * 2.0 / z, n * 3.0 / z, n + f - f * n / z)).length() < 1e-12);
        }
        let mo = lecture_orthographic(-2.0, 2.0, -1.0, 1.0, n, f);
        let c = mo * Vec4::new(2.0, -1.0, f, 1.0);
        // Shirley: the near plane goes to z = +1, the far plane to z = −1.
        assert!((c.truncate() - Vec3::new(1.0, -1.0, -1.0)).length() < 1e-12);
        // Pixel centres: canonical −1 + 1/nx maps to pixel 0.
        let vp = viewport(4.0, 2.0) * Vec4::new(-1.0 + 1.0 / 4.0, 1.0 - 1.0 / 2.0, 0.0, 1.0);
        assert!((vp.truncate() - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn window_to_viewport_plots_cosine() {
        // The lecture's example: x ∈ [0, 2π], cos x ∈ [−1, 1] onto a 640×480 port.
        let m = window_to_viewport([0.0, std::f64::consts::TAU, -1.0, 1.0], [0.0, 640.0, 0.0, 480.0]);
        let p = m * Vec4::new(std::f64::consts::PI, -1.0, 0.0, 1.0);
        assert!((p.truncate() - Vec3::new(320.0, 0.0, 0.0)).length() < 1e-9);
    }

    #[test]
    fn homogenize_examples_from_lecture() {
        assert_eq!(homogenize(Vec4::new(22.0, 121.0, 77.0, 11.0)), Some(Vec3::new(2.0, 11.0, 7.0)));
        assert_eq!(homogenize(Vec4::new(1.0, 5.5, 3.5, 0.5)), Some(Vec3::new(2.0, 11.0, 7.0)));
        assert_eq!(homogenize(Vec4::new(1.0, 1.0, 1.0, 0.0)), None);
    }

    #[test]
    fn look_at_frame_is_orthonormal_and_maps_eye_to_origin() {
        let f = ViewFrame::look_at(Vec3::new(0.0, 2.2, -7.0), Vec3::new(0.0, 0.8, 0.0), Vec3::Y).unwrap();
        assert!((f.u.cross(f.v) - f.w).length() < 1e-12);
        let mv = f.world_to_view();
        assert!(mv.transform_point3(f.eye).length() < 1e-12);
        let gaze = mv.transform_vector3(Vec3::new(0.0, 0.8, 0.0) - f.eye);
        assert!(gaze.x.abs() < 1e-12 && gaze.y.abs() < 1e-12 && gaze.z < 0.0);
        assert!(close(f.view_to_world() * mv, Mat4::IDENTITY, 1e-12));
        assert!(ViewFrame::look_at(Vec3::ZERO, Vec3::Y, Vec3::Y).is_none());
    }

    #[test]
    fn stereo_frusta_share_b_t_n_f_and_see_the_same_screen() {
        let (l, r) = stereo_frusta(0.065, 0.6, 0.5, 0.3, 0.1, 100.0);
        assert_eq!((l.b, l.t, l.n, l.f), (r.b, r.t, r.n, r.f));
        // Project the screen's left edge from each eye onto its near plane.
        let k = 0.1 / 0.6;
        assert!((l.l - (-0.25 + 0.0325) * k).abs() < 1e-15);
        assert!((r.r - (0.25 - 0.0325) * k).abs() < 1e-15);
        assert!(((l.r - l.l) - (r.r - r.l)).abs() < 1e-15);
    }
}
