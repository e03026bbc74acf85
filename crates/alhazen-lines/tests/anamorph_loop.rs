//! The anamorphosis loop (Glaeser §2.4): print a picture for a mirror cylinder, ray-trace the
//! print lying on the floor with the mirror cylinder standing on it, seen from the eye, and
//! compare with the picture itself as the eye would see it on the picture plane: SSIM ≥ 0.9
//! inside the mirror's visible area.

use alhazen_math::{Vec2, Vec3};
use alhazen_mirror::anamorph::{Anamorphosis, paper_size};
use alhazen_render::{Camera, World};

/// A test picture with structure at several scales (stripes, a disk, a gradient), grey levels.
fn picture(uv: Vec2) -> f64 {
    let stripes = 0.25 * (std::f64::consts::TAU * 4.0 * uv.x).sin() * (std::f64::consts::TAU * 3.0 * uv.y).cos();
    let disk = if (uv - Vec2::new(0.35, 0.4)).length() < 0.18 { 0.3 } else { 0.0 };
    (0.3 + 0.4 * uv.y + stripes + disk).clamp(0.0, 1.0)
}

fn ssim(a: &[f64], b: &[f64], mask: &[bool], w: usize, h: usize) -> (f64, usize) {
    let (c1, c2) = (0.01f64.powi(2), 0.03f64.powi(2));
    let r = 3;
    let (mut sum, mut n) = (0.0, 0);
    for y in r..h - r {
        for x in r..w - r {
            let idx: Vec<usize> = (y - r..=y + r).flat_map(|yy| (x - r..=x + r).map(move |xx| yy * w + xx)).collect();
            if !idx.iter().all(|&i| mask[i]) {
                continue;
            }
            let m = idx.len() as f64;
            let (ma, mb) = (idx.iter().map(|&i| a[i]).sum::<f64>() / m, idx.iter().map(|&i| b[i]).sum::<f64>() / m);
            let va = idx.iter().map(|&i| (a[i] - ma).powi(2)).sum::<f64>() / m;
            let vb = idx.iter().map(|&i| (b[i] - mb).powi(2)).sum::<f64>() / m;
            let cov = idx.iter().map(|&i| (a[i] - ma) * (b[i] - mb)).sum::<f64>() / m;
            sum += ((2.0 * ma * mb + c1) * (2.0 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            n += 1;
        }
    }
    (sum / n.max(1) as f64, n)
}

#[test]
fn the_printed_anamorphosis_looks_like_the_picture_in_the_mirror() {
    let (radius, height, eye) = (40.0, 120.0, Vec3::new(0.0, 500.0, 350.0));
    let an = Anamorphosis::new(radius, height, eye, 4.0 / 3.0).unwrap();
    let at = an.place(paper_size("A3").unwrap()).unwrap();
    let dpi = 150.0;
    let mut ink: Vec<f64> = vec![];
    let (pw, ph) = an.print_raster(&at, dpi, |_, row| ink.extend(row.iter().map(|uv| uv.map_or(1.0, picture))));
    let px_mm = 25.4 / dpi;
    let print_at = |paper: Vec2| {
        // Bilinear lookup of the printed raster (paper millimetres).
        let (x, y) = (paper.x / px_mm - 0.5, paper.y / px_mm - 0.5);
        if x < 0.0 || y < 0.0 || x >= (pw - 1) as f64 || y >= (ph - 1) as f64 {
            return None;
        }
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (fx, fy) = (x - x0 as f64, y - y0 as f64);
        let p = |xx: usize, yy: usize| ink[yy * pw as usize + xx];
        let top = p(x0, y0) * (1.0 - fx) + p(x0 + 1, y0) * fx;
        let bottom = p(x0, y0 + 1) * (1.0 - fx) + p(x0 + 1, y0 + 1) * fx;
        Some(top * (1.0 - fy) + bottom * fy)
    };

    // The scene: the mirror cylinder alone, seen from the eye; the floor is the print.
    let scene = alhazen_scene::parse_scene(
        "loop.toml".as_ref(),
        &format!(
            "[render]\nwidth = 240\nheight = 360\n[camera]\neye = [{}, {}, {}]\ntarget = [0, {}, 0]\nfov = 16\n\
             [[object]]\nshape = \"cylinder\"\nbase = [0, 0, 0]\ntop = [0, {height}, 0]\nradius = {radius}\ncapped = false\n\
             material = {{ mirror = 1 }}\n",
            eye.x,
            eye.y,
            eye.z,
            0.5 * height
        ),
    )
    .unwrap();
    let world = World::build(&scene);
    let (w, h) = (scene.render.width as usize, scene.render.height as usize);
    let cam = Camera::new(&scene.camera, w as u32, h as u32);
    let (mut seen, mut truth, mut mask) = (vec![0.0; w * h], vec![0.0; w * h], vec![false; w * h]);
    let picture_plane_normal = Vec3::new(eye.x, 0.0, eye.z).normalize();
    for y in 0..h {
        for x in 0..w {
            let ray = cam.ray(x as f64 + 0.5, y as f64 + 0.5);
            let Some(hit) = world.intersect(&ray, f64::INFINITY) else { continue };
            let n = hit.hit.n;
            // The outside of the mirror (over the rim of the open tube the eye sees its inside).
            if n.dot(ray.dir) >= 0.0 {
                continue;
            }
            let d = ray.dir - n * (2.0 * ray.dir.dot(n));
            if d.y >= 0.0 {
                continue;
            }
            let floor = hit.hit.p + d * (-hit.hit.p.y / d.y);
            let Some(v) = print_at(at.paper_point(Vec2::new(floor.x, floor.z))) else { continue };
            // The picture plane through the axis, facing the eye: what the eye should see.
            let t = -ray.origin.dot(picture_plane_normal) / ray.dir.dot(picture_plane_normal);
            let p = ray.origin + ray.dir * t;
            let corner = an.picture_point(Vec2::ZERO);
            let (across, down) = (an.picture_point(Vec2::X) - corner, an.picture_point(Vec2::Y) - corner);
            let uv = Vec2::new(
                (p - corner).dot(across) / across.length_squared(),
                (p - corner).dot(down) / down.length_squared(),
            );
            if !(0.0..=1.0).contains(&uv.x) || !(0.0..=1.0).contains(&uv.y) {
                continue;
            }
            let i = y * w + x;
            (seen[i], truth[i], mask[i]) = (v, picture(uv), true);
        }
    }
    let covered = mask.iter().filter(|m| **m).count();
    let (s, windows) = ssim(&seen, &truth, &mask, w, h);
    eprintln!("SSIM {s:.4} over {windows} windows ({covered} pixels in the mirror show the picture)");
    assert!(covered > 3000, "{covered}");
    assert!(s >= 0.9, "SSIM {s}");
}
