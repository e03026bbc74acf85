//! Every BSDF's sampling against its density (χ²), its energy bound, reciprocity where the
//! course says it holds, and the η² relation of refraction.

use alhazen_math::{Vec2, Vec3};
use alhazen_render::bsdf::*;
use alhazen_render::sampler::Rng;
use alhazen_scene::bsdf::{Distribution, Microfacets, Shadowing};
use std::f64::consts::PI;

fn facets(distribution: Distribution, au: f64, av: f64, shadowing: Shadowing) -> Microfacet {
    Microfacet::new(&Microfacets { distribution, alpha_u: au, alpha_v: av, shadowing })
}

fn ggx(a: f64) -> Microfacet {
    facets(Distribution::TrowbridgeReitz, a, a, Shadowing::Smith)
}

/// Every non-delta BSDF of the course with a name, in several parameterisations.
fn catalogue() -> Vec<(String, Bsdf)> {
    let albedo = Vec3::new(0.8, 0.6, 0.4);
    let mut list: Vec<(String, Bsdf)> = vec![
        ("lambert".into(), Bsdf::Lambert(Lambert { albedo })),
        ("oren-nayar σ=0.5".into(), Bsdf::OrenNayar(OrenNayar { albedo, sigma: 0.5, interreflection: true })),
        (
            "phong m=20".into(),
            Bsdf::Phong(Phong {
                diffuse: albedo * 0.5,
                ks: 0.5,
                lobe: PhongLobe { exponent: 20.0 },
                transmittance: Vec3::ZERO,
            }),
        ),
        (
            "blinn-phong m=15".into(),
            Bsdf::BlinnPhong(BlinnPhong {
                diffuse: albedo * 0.3,
                ks: 0.7,
                lobe: BlinnPhongLobe { exponent: 15.0, anisotropy: 1.0 },
                transmittance: Vec3::ZERO,
            }),
        ),
        (
            "anisotropic blinn-phong a=0.3".into(),
            Bsdf::BlinnPhong(BlinnPhong {
                diffuse: albedo * 0.3,
                ks: 0.7,
                lobe: BlinnPhongLobe { exponent: 15.0, anisotropy: 0.3 },
                transmittance: Vec3::ZERO,
            }),
        ),
    ];
    for (d, name) in [
        (Distribution::Beckmann, "beckmann"),
        (Distribution::TrowbridgeReitz, "trowbridge-reitz"),
        (Distribution::Gaussian, "gaussian"),
    ] {
        for a in [0.25, 0.6] {
            let g = if d == Distribution::Gaussian { Shadowing::CookTorrance } else { Shadowing::Smith };
            list.push((
                format!("cook-torrance {name} m={a}"),
                Bsdf::CookTorrance(CookTorrance {
                    diffuse: albedo * 0.4,
                    ks: 0.6,
                    lobe: CookTorranceLobe { facets: facets(d, a, a, g), ior: 1.5, schlick: false, layer: 0.0 },
                    transmittance: Vec3::ZERO,
                }),
            ));
            if d != Distribution::Gaussian {
                // A white base layered under the lobe: everything it receives comes back.
                list.push((
                    format!("layered cook-torrance {name} m={a}, white"),
                    Bsdf::CookTorrance(CookTorrance {
                        diffuse: Vec3::ONE,
                        ks: 1.0,
                        lobe: CookTorranceLobe { facets: facets(d, a, a, g), ior: 1.5, schlick: false, layer: 1.0 },
                        transmittance: Vec3::ZERO,
                    }),
                ));
            }
            if d != Distribution::Gaussian {
                list.push((
                    format!("rough conductor {name} m={a}"),
                    Bsdf::Conductor(Conductor {
                        facets: Some(facets(d, a, a, Shadowing::Smith)),
                        eta: Vec3::new(0.2, 0.92, 1.1),
                        k: Vec3::new(3.9, 2.45, 2.14),
                        tint: Vec3::ONE,
                        schlick: false,
                        multiscatter: None,
                        film: None,
                    }),
                ));
                // The light of several facets (GGX's; other facets take single scattering).
                for schlick in [false, true].into_iter().filter(|_| d == Distribution::TrowbridgeReitz) {
                    list.push((
                        format!("rough conductor {name} m={a}, several facets, schlick {schlick}"),
                        Bsdf::Conductor(
                            Conductor {
                                facets: Some(facets(d, a, 0.7 * a, Shadowing::Smith)),
                                eta: Vec3::new(0.2, 0.92, 1.1),
                                k: Vec3::new(3.9, 2.45, 2.14),
                                tint: Vec3::ONE,
                                schlick,
                                multiscatter: None,
                                film: None,
                            }
                            .with_several_facets(),
                        ),
                    ));
                }
                list.push((
                    format!("rough dielectric {name} m={a}"),
                    Bsdf::Dielectric(Dielectric::clear(Some(facets(d, a, a, Shadowing::Smith)), 1.5)),
                ));
            }
        }
    }
    list.push((
        "anisotropic conductor (0.2, 0.5) cook-torrance G".into(),
        Bsdf::Conductor(Conductor {
            facets: Some(facets(Distribution::Beckmann, 0.2, 0.5, Shadowing::CookTorrance)),
            eta: Vec3::splat(1.5),
            k: Vec3::splat(3.0),
            tint: Vec3::ONE,
            schlick: true,
            multiscatter: None,
            film: None,
        }),
    ));
    list.push(("rough plastic ggx m=0.2".into(), Bsdf::Plastic(Plastic::new(albedo, 1.49, Some(ggx(0.2)), false))));
    list.push((
        "rough plastic beckmann m=0.35 nonlinear".into(),
        Bsdf::Plastic(Plastic::new(
            albedo,
            1.6,
            Some(facets(Distribution::Beckmann, 0.35, 0.35, Shadowing::Smith)),
            true,
        )),
    ));
    // Thin translucent sheets: Lambert on both sides, and under a layered lobe.
    list.push((
        "translucent lambert r=0.5 t=(0.2, 0.4, 0.3)".into(),
        Bsdf::CookTorrance(CookTorrance {
            diffuse: Vec3::splat(0.5),
            ks: 0.0,
            lobe: CookTorranceLobe { facets: ggx(1.0), ior: 1.5, schlick: false, layer: 0.0 },
            transmittance: Vec3::new(0.2, 0.4, 0.3),
        }),
    ));
    list.push((
        "layered translucent cook-torrance ggx m=0.2, white".into(),
        Bsdf::CookTorrance(CookTorrance {
            diffuse: Vec3::splat(0.6),
            ks: 1.0,
            lobe: CookTorranceLobe { facets: ggx(0.04), ior: 1.5, schlick: false, layer: 1.0 },
            transmittance: Vec3::splat(0.4),
        }),
    ));
    list.push((
        "mix lambert + rough conductor".into(),
        Bsdf::Mix(Box::new(Mix {
            a: Bsdf::Lambert(Lambert { albedo }),
            b: Bsdf::Conductor(Conductor {
                facets: Some(ggx(0.3)),
                eta: Vec3::splat(0.2),
                k: Vec3::splat(3.0),
                tint: Vec3::ONE,
                schlick: false,
                multiscatter: None,
                film: None,
            }),
            weight: 0.4,
        })),
    ));
    // Clear coats: a glossy one over Lambert, a rougher one of half weight over a rough metal.
    let coat = |alpha: f64| alhazen_render::bsdf::CookTorranceLobe {
        facets: ggx(alpha),
        ior: 1.5,
        schlick: false,
        layer: 0.0,
    };
    list.push((
        "coated lambert, coat ggx m=0.05".into(),
        Bsdf::Coated(Box::new(Coated::new(Bsdf::Lambert(Lambert { albedo }), coat(0.05), 1.0))),
    ));
    list.push((
        "coated rough conductor, coat ggx m=0.3 weight 0.5".into(),
        Bsdf::Coated(Box::new(Coated::new(
            Bsdf::Conductor(Conductor {
                facets: Some(ggx(0.2)),
                eta: Vec3::new(0.2, 0.92, 1.1),
                k: Vec3::new(3.9, 2.45, 2.14),
                tint: Vec3::ONE,
                schlick: false,
                multiscatter: None,
                film: None,
            }),
            coat(0.3),
            0.5,
        ))),
    ));
    // Sheen: velvet over Lambert, a faint rough sheen over rough plastic.
    list.push((
        "sheened lambert, sheen α=0.3".into(),
        Bsdf::Sheened(Box::new(Sheened::new(Bsdf::Lambert(Lambert { albedo }), Vec3::new(1.0, 0.8, 0.6), 0.3))),
    ));
    list.push((
        "sheened rough plastic, sheen α=0.8".into(),
        Bsdf::Sheened(Box::new(Sheened::new(
            Bsdf::Plastic(Plastic::new(albedo, 1.49, Some(ggx(0.2)), false)),
            Vec3::splat(0.3),
            0.8,
        ))),
    ));
    // Tinted glass under a thin film on its outside face (glTF's iridescence under transmission).
    let film =
        alhazen_render::bsdf::ThinFilm { weight: 0.9, ior: 1.33, thickness: 350.0, outside: 1.0, wavelengths: None };
    list.push((
        "rough dielectric tinted, under a film".into(),
        Bsdf::Dielectric(Dielectric {
            facets: Some(ggx(0.3)),
            eta: 1.5,
            schlick: false,
            dispersive: false,
            thin: false,
            tint: Vec3::new(0.9, 0.7, 0.5),
            film: Some(film),
        }),
    ));
    // Thin films (glTF's iridescence) over the metallic–roughness model's metal and coating.
    for (metallic, multiscatter) in [(1.0, false), (1.0, true), (0.0, false), (0.4, false)] {
        list.push((
            format!("metallic-roughness {metallic} under a film, multiscatter {multiscatter}"),
            filmed(metallic, multiscatter),
        ));
    }
    list
}

/// glTF's metallic–roughness surface of `metallic` under a thin film, as the path tracer builds it.
fn filmed(metallic: f64, multiscatter: bool) -> Bsdf {
    filmed_by(metallic, multiscatter, 0.8)
}

fn filmed_by(metallic: f64, multiscatter: bool, factor: f64) -> Bsdf {
    use alhazen_scene::bsdf::{Anisotropy, BsdfDesc, Iridescence};
    let desc = BsdfDesc::MetallicRoughness {
        // (Pale: the coating's diffuse term is layered under its own lobe, but the film's lobe
        // that replaces part of it may reflect more than the lobe would.)
        base: alhazen_scene::Texture::Solid(Vec3::new(0.6, 0.45, 0.3)),
        metallic,
        roughness: 0.4,
        map: None,
        ior: 1.5,
        specular: 1.0,
        multiscatter,
        anisotropy: Anisotropy::default(),
        anisotropy_map: None,
        iridescence: Some(Box::new(Iridescence {
            factor,
            ior: 1.8,
            thickness: [100.0, 450.0],
            outside: 1.0,
            factor_map: None,
            thickness_map: None,
        })),
        specular_map: None,
        specular_color_map: None,
        translucency: Default::default(),
        translucency_map: None,
        translucency_color_map: None,
    };
    let m = alhazen_scene::Material::from_bsdf("film", desc);
    alhazen_render::bsdf::bsdf_at(&m, Vec2::ZERO, Vec3::ONE, &[], alhazen_render::bsdf::ColorMode::Rgb)
}

fn direction(theta_deg: f64, phi: f64) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos())
}

/// Regularised upper incomplete gamma `Q(a, x)` (series / continued fraction).
fn gamma_q(a: f64, x: f64) -> f64 {
    fn ln_gamma(x: f64) -> f64 {
        // Lanczos, g = 7.
        const C: [f64; 9] = [
            0.999_999_999_999_809_9,
            676.5203681218851,
            -1259.1392167224028,
            771.323_428_777_653_1,
            -176.615_029_162_140_6,
            12.507343278686905,
            -0.13857109526572012,
            9.984_369_578_019_572e-6,
            1.5056327351493116e-7,
        ];
        let x = x - 1.0;
        let t = x + 7.5;
        let s: f64 = C[0] + (1..9).map(|i| C[i] / (x + i as f64)).sum::<f64>();
        0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + s.ln()
    }
    if x < a + 1.0 {
        let (mut sum, mut term, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..1000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * (-x + a * x.ln() - ln_gamma(a)).exp()
    } else {
        let (mut b, mut c, mut d) = (x + 1.0 - a, 1.0 / 1e-300, 1.0 / (x + 1.0 - a));
        let mut h = d;
        for i in 1..1000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            d = if d.abs() < 1e-300 { 1e-300 } else { d };
            c = b + an / c;
            c = if c.abs() < 1e-300 { 1e-300 } else { c };
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (-x + a * x.ln() - ln_gamma(a)).exp() * h
    }
}

const CELLS_THETA: usize = 24;
const CELLS_PHI: usize = 48;

fn cell_of(l: Vec3) -> usize {
    let theta = l.z.clamp(-1.0, 1.0).acos();
    let c = ((theta / PI * CELLS_THETA as f64) as usize).min(CELLS_THETA - 1);
    let phi = l.y.atan2(l.x).rem_euclid(2.0 * PI);
    let p = ((phi / (2.0 * PI) * CELLS_PHI as f64) as usize).min(CELLS_PHI - 1);
    c * CELLS_PHI + p
}

/// Expected fraction of samples per cell: the pdf integrated by a 12×12 midpoint rule per cell
/// in (ϑ, φ), `dω = sin ϑ dϑ dφ` — 96 × 12 in the two rows of cells along the horizon, where
/// rough refraction at grazing incidence peaks (visible-normal sampling sends samples there).
fn expected_fractions(b: &Bsdf, v: Vec3) -> Vec<f64> {
    let sub = 12;
    let (dt, dp) = (PI / CELLS_THETA as f64, 2.0 * PI / CELLS_PHI as f64);
    let mut out = vec![0.0; CELLS_THETA * CELLS_PHI];
    for ti in 0..CELLS_THETA {
        let sub_t = if ti + 1 == CELLS_THETA / 2 || ti == CELLS_THETA / 2 { 8 * sub } else { sub };
        for pi in 0..CELLS_PHI {
            let mut sum = 0.0;
            for a in 0..sub_t {
                let (st, ct) = (dt * (ti as f64 + (a as f64 + 0.5) / sub_t as f64)).sin_cos();
                for c in 0..sub {
                    let phi = dp * (pi as f64 + (c as f64 + 0.5) / sub as f64);
                    sum += b.pdf(v, Vec3::new(st * phi.cos(), st * phi.sin(), ct)) * st;
                }
            }
            out[ti * CELLS_PHI + pi] = sum * dt * dp / (sub_t * sub) as f64;
        }
    }
    out
}

/// χ² goodness of fit of `sample` against `pdf`, cells with fewer than 5 expected pooled.
fn chi2_p_value(b: &Bsdf, v: Vec3, n: usize, seed: u64) -> f64 {
    let mut rng = Rng::for_sample(seed, 1, 2, 3);
    let mut observed = vec![0.0; CELLS_THETA * CELLS_PHI];
    for _ in 0..n {
        let (uc, u) = (rng.uniform(), Vec2::new(rng.uniform(), rng.uniform()));
        let Some(s) = b.sample(v, uc, u) else { continue };
        assert!(!s.delta);
        let pdf = b.pdf(v, s.l);
        assert!((s.pdf - pdf).abs() <= 1e-6 * pdf.max(1e-3), "sampled pdf {} vs pdf() {}", s.pdf, pdf);
        let f = b.eval(v, s.l);
        assert!((s.f - f).abs().max_element() <= 1e-6 * f.max_element().max(1e-3), "f {} vs {}", s.f, f);
        observed[cell_of(s.l)] += 1.0;
    }
    let expected: Vec<f64> = expected_fractions(b, v).iter().map(|e| e * n as f64).collect();
    let (mut chi2, mut dof, mut pooled_o, mut pooled_e) = (0.0, 0usize, 0.0, 0.0);
    for (o, e) in observed.iter().zip(&expected) {
        if *e < 5.0 {
            pooled_o += o;
            pooled_e += e;
        } else {
            chi2 += (o - e).powi(2) / e;
            dof += 1;
        }
    }
    if pooled_e >= 5.0 {
        chi2 += (pooled_o - pooled_e).powi(2) / pooled_e;
        dof += 1;
    } else {
        assert!(pooled_o < 10.0 + 5.0 * pooled_e, "{pooled_o} samples where the pdf expects {pooled_e}");
    }
    gamma_q((dof - 1) as f64 / 2.0, chi2 / 2.0)
}

#[test]
fn sampling_matches_the_density_of_every_bsdf_chi2() {
    let cases = catalogue();
    let angles = [10.0, 45.0, 80.0];
    let tests = cases.len() * angles.len();
    // Bonferroni: the whole suite fails with probability 1 % when everything is right.
    let alpha = 0.01 / tests as f64;
    for (k, (name, b)) in cases.iter().enumerate() {
        for (j, theta) in angles.iter().enumerate() {
            let v = direction(*theta, 0.7);
            let p = chi2_p_value(b, v, 100_000, (k * 10 + j) as u64);
            assert!(p > alpha, "{name} at {theta}°: p = {p:.3e}");
        }
    }
}

#[test]
fn rough_dielectric_sampling_from_inside_matches_its_density() {
    let b = Bsdf::Dielectric(Dielectric::clear(Some(ggx(0.4)), 1.5));
    for theta in [20.0, 60.0] {
        let v = -direction(theta, 1.1);
        let p = chi2_p_value(&b, v, 400_000, 98);
        assert!(p > 1e-3, "from inside at {theta}°: p = {p:.3e}");
    }
}

/// `∫ ρ cos` over all outgoing directions by importance sampling, with its standard error.
fn albedo(b: &Bsdf, v: Vec3, n: usize) -> (Vec3, f64) {
    let mut rng = Rng::for_sample(5, 6, 7, 8);
    let (mut sum, mut sum2) = (Vec3::ZERO, 0.0);
    for _ in 0..n {
        let Some(s) = b.sample(v, rng.uniform(), Vec2::new(rng.uniform(), rng.uniform())) else { continue };
        let w = s.f * s.l.z.abs() / s.pdf;
        sum += w;
        sum2 += w.max_element().powi(2);
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean.max_element().powi(2)).max(0.0);
    (mean, (var / n as f64).sqrt())
}

#[test]
fn no_bsdf_reflects_more_energy_than_it_receives() {
    for (name, b) in catalogue() {
        for theta in [0.0, 30.0, 60.0, 85.0] {
            let (a, err) = albedo(&b, direction(theta, 0.3), 100_000);
            assert!(a.max_element() <= 1.0 + 4.0 * err + 1e-3, "{name} at {theta}°: ∫ρcos = {a} ± {err}");
        }
    }
}

#[test]
fn lambert_with_albedo_one_conserves_energy_exactly() {
    let b = Bsdf::Lambert(Lambert { albedo: Vec3::ONE });
    for theta in [0.0, 45.0, 89.0] {
        let (a, err) = albedo(&b, direction(theta, 0.0), 10_000);
        assert!((a - Vec3::ONE).abs().max_element() < 1e-12 && err < 1e-9, "{a}");
    }
}

#[test]
fn smooth_dielectric_splits_energy_without_loss() {
    // Importance transport: reflected F plus transmitted (1 − F) once the η² of radiance is undone.
    for eta in [1.33, 1.5, 2.4] {
        let b = Bsdf::Dielectric(Dielectric::clear(None, eta));
        for v in [direction(0.0, 0.0), direction(50.0, 1.0), -direction(30.0, 2.0), -direction(70.0, 2.0)] {
            let (mut total, n) = (0.0, 20_000);
            let mut rng = Rng::for_sample(1, 1, 1, 1);
            for _ in 0..n {
                let s = b.sample(v, rng.uniform(), Vec2::ZERO).unwrap();
                assert!(s.delta);
                total += (s.f * s.l.z.abs() / s.pdf).x * s.eta * s.eta;
            }
            assert!((total / n as f64 - 1.0).abs() < 1e-9, "η = {eta}, v = {v}: {}", total / n as f64);
        }
    }
}

#[test]
fn eval_pdf_gives_eval_and_pdf_bit_for_bit() {
    let mut rng = Rng::for_sample(3, 1, 4, 1);
    let mut cases = catalogue();
    cases.push(("smooth plastic".into(), Bsdf::Plastic(Plastic::new(Vec3::splat(0.5), 1.5, None, false))));
    for (name, b) in cases {
        for _ in 0..300 {
            let v = direction(rng.uniform() * 180.0, rng.uniform() * 2.0 * PI);
            let l = direction(rng.uniform() * 180.0, rng.uniform() * 2.0 * PI);
            let (f, pdf) = b.eval_pdf(v, l);
            assert_eq!(f.to_array().map(f64::to_bits), b.eval(v, l).to_array().map(f64::to_bits), "{name}");
            assert_eq!(pdf.to_bits(), b.pdf(v, l).to_bits(), "{name}");
        }
    }
}

#[test]
fn white_smooth_plastic_reflects_all_it_receives() {
    // The coat's mirror F plus the base's closed-form bounces: exactly 1 in theory; the
    // transmittance's polynomial and the inner reflectance's quadrature leave a small error.
    let b = Bsdf::Plastic(Plastic::new(Vec3::ONE, 1.5, None, false));
    for theta in [0.0, 40.0, 75.0] {
        let (a, err) = albedo(&b, direction(theta, 0.2), 200_000);
        assert!((a.x - 1.0).abs() < 4.0 * err + 3e-3, "at {theta}°: {a} ± {err}");
    }
}

/// A white base layered under a Cook–Torrance lobe (glTF's dielectric, as Cycles layers it)
/// gives back what it receives at every angle, within the lobe's tabulated albedo; with the
/// constant weight `1 − F(0)` it gave back 9 % more at 85°. So does a translucent one whose
/// reflected and transmitted parts sum to white (its lobe's samples that leave below the
/// surface counted in the transmitted density: left out, it gave back 1 % more at 89°).
#[test]
fn white_layered_cook_torrance_reflects_all_it_receives() {
    for (name, b) in catalogue().into_iter().filter(|(name, _)| name.starts_with("layered")) {
        // (From below too: a translucent sheet has two faces alike.)
        for theta in [0.0, 40.0, 75.0, 85.0, 120.0] {
            let (a, err) = albedo(&b, direction(theta, 0.2), 200_000);
            assert!((a.x - 1.0).abs() < 4.0 * err + 5e-3, "{name} at {theta}°: {a} ± {err}");
        }
    }
}

#[test]
fn reciprocal_brdfs_satisfy_helmholtz() {
    let mut rng = Rng::for_sample(2, 2, 2, 2);
    for (name, b) in catalogue() {
        if name.starts_with("rough dielectric") {
            continue; // dielectrics obey the η² law below
        }
        if name.starts_with("coated")
            || name.starts_with("sheened")
            || name.starts_with("layered")
            || name.contains("metallic-roughness 0")
        {
            continue; // the base under a coat is weighed by what the coat lets through towards the viewer only (glTF's and Cycles' layering)
        }
        for _ in 0..200 {
            let a = direction(rng.uniform() * 89.0, rng.uniform() * 2.0 * PI);
            let c = direction(rng.uniform() * 89.0, rng.uniform() * 2.0 * PI);
            let (f1, f2) = (b.eval(a, c), b.eval(c, a));
            assert!((f1 - f2).abs().max_element() <= 1e-9 * f1.max_element().max(1.0), "{name}: {f1} vs {f2}");
        }
    }
}

#[test]
fn the_course_phong_is_not_reciprocal_but_the_normalised_one_is() {
    // The course's Phong term s·(r·v)^m is added to radiance, i.e. ρ = s(r·v)^m/⟨n,l⟩ as a BRDF:
    // swapping l and v changes the denominator. The normalised lobe drops that division.
    let (a, c) = (direction(10.0, 0.0), direction(60.0, 2.5));
    let r = |l: Vec3| Vec3::new(-l.x, -l.y, l.z);
    let course = |v: Vec3, l: Vec3| r(l).dot(v).max(0.0).powf(10.0) / l.z;
    assert!((course(a, c) - course(c, a)).abs() > 0.1 * course(a, c));
    let b = Bsdf::Phong(Phong {
        diffuse: Vec3::ZERO,
        ks: 1.0,
        lobe: PhongLobe { exponent: 10.0 },
        transmittance: Vec3::ZERO,
    });
    assert!((b.eval(a, c).x - b.eval(c, a).x).abs() < 1e-12);
}

#[test]
fn refraction_obeys_the_course_eta_squared_law() {
    // η₁² ρ(l, v) = η₂² ρ(v, l), η₁ on the light's side, η₂ on the viewer's.
    let eta = 1.5;
    let b = Bsdf::Dielectric(Dielectric::clear(Some(ggx(0.35)), eta));
    let mut rng = Rng::for_sample(3, 3, 3, 3);
    let mut checked = 0;
    for _ in 0..500 {
        let v = direction(rng.uniform() * 85.0, rng.uniform() * 2.0 * PI);
        let l = -direction(rng.uniform() * 85.0, rng.uniform() * 2.0 * PI);
        let (f_vl, f_lv) = (b.eval(v, l).x, b.eval(l, v).x);
        if f_vl == 0.0 && f_lv == 0.0 {
            continue;
        }
        // l inside (η₁ = η), v outside (η₂ = 1).
        assert!((eta * eta * f_vl - f_lv).abs() <= 1e-9 * f_lv.max(1e-6), "{f_vl} {f_lv}");
        checked += 1;
    }
    assert!(checked > 100);
}

#[test]
fn oren_nayar_with_zero_roughness_is_lambert() {
    let a = Vec3::new(0.3, 0.6, 0.9);
    let on = Bsdf::OrenNayar(OrenNayar { albedo: a, sigma: 0.0, interreflection: true });
    let l = Bsdf::Lambert(Lambert { albedo: a });
    for (t1, t2) in [(10.0, 70.0), (45.0, 45.0), (80.0, 5.0)] {
        let (v, w) = (direction(t1, 0.2), direction(t2, 2.0));
        assert!((on.eval(v, w) - l.eval(v, w)).abs().max_element() < 1e-15);
    }
}

#[test]
fn conductor_fresnel_matches_known_values() {
    use alhazen_render::bsdf::Conductor;
    // A dielectric is a conductor with κ = 0; at normal incidence ((η−1)² + κ²)/((η+1)² + κ²).
    let c = |eta: f64, k: f64| Conductor {
        facets: None,
        eta: Vec3::splat(eta),
        k: Vec3::splat(k),
        tint: Vec3::ONE,
        schlick: false,
        multiscatter: None,
        film: None,
    };
    let f = c(1.5, 0.0).fresnel(1.0).x;
    assert!((f - 0.04).abs() < 1e-12);
    let (eta, k) = (0.2, 3.9);
    let want = ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k);
    assert!((c(eta, k).fresnel(1.0).x - want).abs() < 1e-12);
    assert!((c(eta, k).fresnel(0.0).x - 1.0).abs() < 1e-9, "grazing incidence reflects everything");
    for cos in [0.2, 0.5, 0.9] {
        let dielectric = alhazen_render::optics::fresnel_dielectric(cos, 1.5);
        assert!((c(1.5, 0.0).fresnel(cos).x - dielectric).abs() < 1e-12, "κ = 0 is the course's formula");
    }
}

/// A thin sheet of glass reflects `R' = 2R/(1 + R)` of the light from either side (`R` its
/// faces' Fresnel reflectance), mirrored, and lets the rest through undeviated; it absorbs
/// nothing (every sample's weight is 1).
#[test]
fn a_thin_sheet_reflects_both_faces_and_passes_the_rest_straight() {
    let sheet = Dielectric {
        facets: None,
        eta: 1.5,
        schlick: false,
        dispersive: false,
        thin: true,
        tint: Vec3::ONE,
        film: None,
    };
    for (theta, side) in [(0.0, 1.0), (40.0, 1.0), (75.0, -1.0), (89.0, -1.0)] {
        let v = direction(theta, 0.7) * Vec3::new(1.0, 1.0, side);
        let cos = v.z.abs();
        let r = alhazen_render::optics::fresnel_dielectric(cos, 1.5);
        let want = 2.0 * r / (1.0 + r);
        let n = 20_000;
        let mut reflected = 0;
        for k in 0..n {
            let s = sheet.sample(v, (k as f64 + 0.5) / n as f64, Vec2::ZERO).unwrap();
            assert!(s.delta && s.eta == 1.0);
            assert!(((s.f * s.l.z.abs() / s.pdf) - Vec3::ONE).abs().max_element() < 1e-12);
            if s.l.z * v.z > 0.0 {
                reflected += 1;
                assert!((s.l - Vec3::new(-v.x, -v.y, v.z)).length() < 1e-12);
            } else {
                assert_eq!(s.l, -v);
            }
        }
        let got = reflected as f64 / n as f64;
        assert!((got - want).abs() < 1e-3, "θ {theta}: reflected {got}, want {want}");
    }
}

/// A white rough metal (a mirror's Fresnel term, 1 at every angle) that gives back the light of
/// several facets reflects all the light at every angle and roughness — a white furnace — where
/// single scattering loses up to half of it on the roughest facets.
#[test]
fn several_facets_give_the_white_furnace_back_its_light() {
    use alhazen_render::bsdf::Conductor;
    let white = |alpha: f64, multiscatter: bool| {
        let c = Conductor {
            facets: Some(facets(Distribution::TrowbridgeReitz, alpha, alpha, Shadowing::Smith)),
            eta: Vec3::ZERO,
            k: Vec3::ZERO,
            tint: Vec3::ONE,
            schlick: false,
            multiscatter: None,
            film: None,
        };
        Bsdf::Conductor(if multiscatter { c.with_several_facets() } else { c })
    };
    // The albedo towards `v` by sampling: the mean of f·cos/pdf over a stratified grid.
    let albedo = |b: &Bsdf, v: Vec3| {
        let n = 128;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                let uc = ((i * n + j) as f64 * 0.618_033_988_749_894_9).fract();
                if let Some(s) = b.sample(v, uc, u) {
                    sum += s.f.x * s.l.z.abs() / s.pdf;
                }
            }
        }
        sum / (n * n) as f64
    };
    for alpha in [0.1, 0.4, 0.7, 1.0] {
        for theta in [0.0, 40.0, 75.0, 85.0, 88.0] {
            let v = direction(theta, 0.3);
            let (single, several) = (albedo(&white(alpha, false), v), albedo(&white(alpha, true), v));
            assert!((several - 1.0).abs() < 0.03, "α {alpha}, ϑ {theta}: {several} (single {single})");
            assert!(several >= single - 1e-9, "α {alpha}, ϑ {theta}: {several} < {single}");
        }
    }
    let v = direction(40.0, 0.3);
    assert!(albedo(&white(1.0, false), v) < 0.75, "the roughest single scattering loses light");
}

/// A metallic–roughness coating's specular maps (glTF's `specularTexture` and
/// `specularColorTexture`) act per point: the first scales its specular strength (`k_s =
/// specular · texel`, the diffuse layered under it), the second its normal-incidence
/// reflectance (`F(0)` times the texel's mean, through the index with that reflectance).
#[test]
fn specular_maps_shape_the_coating_per_point() {
    use alhazen_scene::bsdf::{Anisotropy, BsdfDesc};
    let texel = std::sync::Arc::new(alhazen_scene::ImageData::new(1, 1, vec![[0.25; 3]]));
    let map = alhazen_scene::Texture::Image { image: 0, scale: Vec2::ONE, offset: Vec2::ZERO, rotation: 0.0 };
    let desc = |specular_map, specular_color_map| BsdfDesc::MetallicRoughness {
        base: alhazen_scene::Texture::Solid(Vec3::splat(0.5)),
        metallic: 0.0,
        roughness: 0.4,
        map: None,
        ior: 1.5,
        specular: 0.8,
        multiscatter: false,
        anisotropy: Anisotropy::default(),
        anisotropy_map: None,
        iridescence: None,
        specular_map,
        specular_color_map,
        translucency: Default::default(),
        translucency_map: None,
        translucency_color_map: None,
    };
    let coating = |specular_map, specular_color_map| {
        let m = alhazen_scene::Material::from_bsdf("m", desc(specular_map, specular_color_map));
        let images = std::slice::from_ref(&texel);
        match alhazen_render::bsdf::bsdf_at(&m, Vec2::ZERO, Vec3::ONE, images, alhazen_render::bsdf::ColorMode::Rgb) {
            Bsdf::Mix(mix) => match mix.b {
                Bsdf::CookTorrance(c) => {
                    assert_eq!(c.lobe.layer, c.ks, "the diffuse layered under the lobe");
                    (c.ks, c.diffuse.x, c.lobe.ior)
                }
                other => panic!("{other:?}"),
            },
            other => panic!("{other:?}"),
        }
    };
    assert_eq!(coating(None, None), (0.8, 0.5, 1.5));
    let (ks, diffuse, _) = coating(Some(map.clone()), None);
    assert!((ks - 0.2).abs() < 1e-12 && diffuse == 0.5, "{ks} {diffuse}");
    // F(0) of 1.5 is 0.04; a quarter of it is 0.01, the reflectance of an index of 11/9.
    let (ks, diffuse, ior) = coating(None, Some(map));
    assert!((ior - 11.0 / 9.0).abs() < 1e-12 && ks == 0.8 && diffuse == 0.5, "{ior} {diffuse}");
}
