//! Descriptions of the physically based scattering functions of the course (§"Physically based
//! models"): plain data, evaluated by `alhazen-render`'s `bsdf` module.
//!
//! A material without an explicit `bsdf` is read by the path tracer as: a smooth dielectric when
//! it is transparent, else Lambert (`color × diffuse`) plus a perfect mirror of weight `mirror`.

use crate::model::{FresnelMode, Rgb, Texture};

use alhazen_math::Vec3;

/// The microfacet normal distribution `D`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distribution {
    /// Beckmann–Spizzichino (Cook–Torrance 1981).
    Beckmann,
    /// Trowbridge–Reitz ("GGX").
    TrowbridgeReitz,
    /// The Gaussian `a·exp(−(ϑ/m)²)` of Torrance–Sparrow (1967), normalised numerically.
    Gaussian,
}

/// The shadowing–masking term `G`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shadowing {
    /// The V-groove `min{1, 2⟨h,n⟩⟨v,n⟩/⟨v,h⟩, 2⟨h,n⟩⟨l,n⟩/⟨l,h⟩}`.
    CookTorrance,
    /// Smith's separable `G₁(l)·G₁(v)` for the chosen distribution.
    Smith,
}

/// A rough surface: distribution, roughness along the tangent `u` and `v` (`m_u`, `m_v`; equal
/// for isotropic surfaces) and shadowing term.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacets {
    /// `D`.
    pub distribution: Distribution,
    /// `m_u` (the course's `m`; Mitsuba's `alpha_u`).
    pub alpha_u: f64,
    /// `m_v`.
    pub alpha_v: f64,
    /// `G`.
    pub shadowing: Shadowing,
}

/// An index of refraction, possibly depending on wavelength (nanometres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Ior {
    /// The same for every wavelength.
    Constant(f64),
    /// Cauchy: `η(λ) = A + B/λ²` with `λ` in micrometres.
    Cauchy {
        /// `A`.
        a: f64,
        /// `B` in µm².
        b: f64,
    },
    /// Sellmeier: `η² = 1 + Σ Bᵢλ²/(λ² − Cᵢ)` with `λ` in micrometres.
    Sellmeier {
        /// `B₁..B₃`.
        b: [f64; 3],
        /// `C₁..C₃` in µm².
        c: [f64; 3],
    },
}

impl Ior {
    /// The index at wavelength `lambda_nm`.
    pub fn at(&self, lambda_nm: f64) -> f64 {
        let l = lambda_nm * 1e-3;
        match *self {
            Ior::Constant(eta) => eta,
            Ior::Cauchy { a, b } => a + b / (l * l),
            Ior::Sellmeier { b, c } => {
                let l2 = l * l;
                (1.0 + (0..3).map(|i| b[i] * l2 / (l2 - c[i])).sum::<f64>()).sqrt()
            }
        }
    }

    /// The index at the sodium D line (589.3 nm), used where light is not split by wavelength.
    pub fn nominal(&self) -> f64 {
        self.at(589.3)
    }

    /// True when the index varies with wavelength.
    pub fn is_dispersive(&self) -> bool {
        !matches!(self, Ior::Constant(_))
    }
}

/// A scattering function.
// A description, made once per material and read where a BSDF is built (the tracers' own
// `Bsdf` is what hot loops copy): the metallic–roughness variant's maps kept inline.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum BsdfDesc {
    /// `ρ = albedo/π`.
    Lambert {
        /// Albedo.
        albedo: Texture,
    },
    /// Oren–Nayar, the course's `ρ_d,1` plus optionally the interreflection term `ρ_d,2`.
    OrenNayar {
        /// Albedo `c_λ`.
        albedo: Texture,
        /// Roughness `σ` in radians.
        sigma: f64,
        /// Add `ρ_d,2`.
        interreflection: bool,
    },
    /// Energy-normalised Phong: `kd·albedo/π + ks (m+2)/(2π) cos^m α`.
    Phong {
        /// Diffuse albedo.
        albedo: Texture,
        /// Diffuse weight `k_d`.
        kd: f64,
        /// Specular weight `k_s`.
        ks: f64,
        /// `m`.
        exponent: f64,
    },
    /// Energy-normalised (anisotropic) Blinn–Phong with the course's `⟨ĥ, n⟩^{2m}` lobe.
    BlinnPhong {
        /// Diffuse albedo.
        albedo: Texture,
        /// Diffuse weight `k_d`.
        kd: f64,
        /// Specular weight `k_s`.
        ks: f64,
        /// `m` (the lobe is `cos^{2m}`).
        exponent: f64,
        /// The course's `a ∈ (0, 1]`: 1 is isotropic.
        anisotropy: f64,
        /// Direction of the scratches, projected on the tangent plane.
        scratches: Vec3,
    },
    /// `v(kd ρ_d + ks ρ_s)` with Lambert `ρ_d` and the microfacet `ρ_s = DGF/(4⟨l,n⟩⟨v,n⟩)` of a
    /// dielectric coating of index `ior`.
    CookTorrance {
        /// Diffuse albedo.
        albedo: Texture,
        /// Diffuse weight `k_d`.
        kd: f64,
        /// Specular weight `k_s`.
        ks: f64,
        /// `D`, roughness, `G`.
        facets: Microfacets,
        /// Index of refraction for `F`.
        ior: f64,
        /// Exact or Schlick.
        fresnel: FresnelMode,
        /// The diffuse term weighed by what the specular lobe leaves towards the viewer,
        /// `k_d·(1 − k_s·E(μ_o))` with `E` the lobe's directional albedo (Cycles' Principled
        /// BSDF's albedo scaling, what a glTF dielectric is layered as): energy is kept at every
        /// angle, where a constant `k_d` sends back more than arrives at grazing angles.
        layered: bool,
        /// What passes through diffusely to the other side, `transmittance/π` there (black for
        /// none): a thin translucent sheet — a leaf, paper, a lampshade (pbrt's
        /// `diffusetransmission`, glTF's `KHR_materials_diffuse_transmission`). Weighed as the
        /// diffuse term is when layered, not by `kd`.
        transmittance: Texture,
    },
    /// Plastic: a diffuse base under a dielectric coat of index `ior`, smooth when `facets` is
    /// `None`, the light bouncing between base and coat summed in closed form (Mitsuba 3's
    /// `plastic` and `roughplastic`).
    Plastic {
        /// The base's albedo.
        albedo: Texture,
        /// The coat's index relative to the outside.
        ior: f64,
        /// The coat's roughness, or smooth.
        facets: Option<Microfacets>,
        /// Colour-dependent inner bounces (`albedo / (1 − albedo·R)` rather than
        /// `albedo / (1 − R)`): more saturated colours.
        nonlinear: bool,
    },
    /// A metal: Fresnel with a complex index `η + iκ` per RGB channel; smooth when `facets` is `None`.
    Conductor {
        /// Roughness, or a perfect mirror.
        facets: Option<Microfacets>,
        /// Real part `η`.
        eta: Rgb,
        /// Imaginary part `κ`.
        k: Rgb,
        /// Multiplier (1 is physical).
        tint: Rgb,
        /// Exact or Schlick (from the normal-incidence reflectance).
        fresnel: FresnelMode,
        /// Rough: the light that meets several facets is given back (Kulla and Conty's lobe,
        /// the energy Cycles' multiple-scattering GGX keeps); false: single scattering, as
        /// pbrt and Mitsuba.
        multiscatter: bool,
    },
    /// Glass and the like: reflection and refraction with the course's transmission term.
    Dielectric {
        /// Roughness, or smooth when `None`.
        facets: Option<Microfacets>,
        /// Index of refraction of the inside relative to the outside.
        ior: Ior,
        /// Exact or Schlick.
        fresnel: FresnelMode,
        /// What refracted light keeps at each crossing, per channel (white: clear glass; glTF's
        /// transmission is tinted by the base colour, Mitsuba's by `specular_transmittance`).
        transmittance: Texture,
        /// A thin film on its outside face (glTF's iridescence over transmission); none by
        /// default.
        film: Option<Box<Iridescence>>,
    },
    /// A thin sheet of glass (a window pane): light passes straight through it, or is
    /// reflected by its two faces and every bounce between them, `R' = 2R/(1 + R)` of it for a
    /// face's Fresnel reflectance `R` (Mitsuba's `thindielectric`).
    ThinDielectric {
        /// Index of refraction of the sheet relative to the outside.
        ior: f64,
    },
    /// glTF 2.0's metallic–roughness material with its values read per point
    /// ([`BsdfDesc::metallic_roughness_at`]): the base colour, and metallic and roughness as
    /// their factors times the map's blue and green channels (read linearly), where there is
    /// a map.
    MetallicRoughness {
        /// Base colour.
        base: Texture,
        /// Metalness factor.
        metallic: f64,
        /// Perceptual roughness factor (`α = roughness²`).
        roughness: f64,
        /// The metallic–roughness map: an image texture ([`Texture::Image`], read linearly)
        /// with its own placement (scale, turn, shift).
        map: Option<Texture>,
        /// The coating's index of refraction.
        ior: f64,
        /// The strength of the coating's specular lobe (glTF's `KHR_materials_specular`
        /// `specularFactor`, 1 without it): Cook–Torrance's `ks`, the diffuse layered under it
        /// (weighted by `1 − specular·E(μ_o)`).
        specular: f64,
        /// The metal's light of several facets ([`BsdfDesc::Conductor`]'s `multiscatter`).
        multiscatter: bool,
        /// Facets stretched along a direction of brushing (glTF's `KHR_materials_anisotropy`,
        /// principled's `anisotropic`); none by default.
        anisotropy: Anisotropy,
        /// Where the brushing varies over the surface (glTF's `anisotropyTexture`, read
        /// linearly): each texel's red and green `2c − 1` the direction in the frame of the
        /// tangent and bitangent (turned further by the rotation), its blue multiplying the
        /// strength.
        anisotropy_map: Option<Texture>,
        /// A thin film over both lobes (glTF's `KHR_materials_iridescence`); none by default.
        iridescence: Option<Box<Iridescence>>,
        /// Where the coating's specular strength varies: `specular` times the map's first
        /// channel (read linearly; glTF's `specularTexture` is its alpha).
        specular_map: Option<Texture>,
        /// Where the coating's normal-incidence reflectance varies: `F(0)` of `ior` times the
        /// map's mean colour, the coating's index found from that (glTF's `specularColorTexture`).
        specular_color_map: Option<Texture>,
        /// The share of the coating's diffuse light that passes through (glTF's
        /// `KHR_materials_diffuse_transmission`).
        translucency: Translucency,
        /// Where that share varies: its `factor` times the map's first channel (read linearly;
        /// glTF's `diffuseTransmissionTexture` is its alpha).
        translucency_map: Option<Texture>,
        /// Where the colour of the passing light varies: its `color` times the map's.
        translucency_color_map: Option<Texture>,
    },
    /// A clear coat over `base` (car paint, lacquer; glTF's `KHR_materials_clearcoat`): a
    /// dielectric microfacet layer of `weight` reflecting `weight·D G F/(4⟨l,n⟩⟨v,n⟩)`, the
    /// base below weighted by one minus the coat's albedo towards the viewer.
    Coated {
        /// What lies under the coat.
        base: Box<BsdfDesc>,
        /// The coat's weight in `[0, 1]`.
        weight: f64,
        /// The coat's facets (GGX in the importers; at least `α = 0.01`).
        facets: Microfacets,
        /// The coat's index of refraction (1.5 in glTF).
        ior: f64,
        /// Where the weight varies: `weight` times the map's red channel (read linearly; glTF's
        /// `clearcoatTexture`).
        weight_map: Option<Texture>,
        /// Where the roughness varies: the facets' roughness `√α` times the map's green channel
        /// (read linearly, `α` at least 0.01; glTF's `clearcoatRoughnessTexture`).
        roughness_map: Option<Texture>,
    },
    /// Sheen over `base` (velvet, satin; glTF's `KHR_materials_sheen`): Estevez and Kulla's
    /// "Charlie" fibres of colour `color` reflecting `color·ρ_s`, the base below weighted by one
    /// minus the sheen's albedo towards the viewer.
    Sheened {
        /// What lies under the sheen.
        base: Box<BsdfDesc>,
        /// The sheen's colour (0: none), a texture where it varies.
        color: Texture,
        /// The fibres' roughness `r ∈ [0, 1]` (`α = r²`, at least 10⁻³).
        roughness: f64,
        /// Where the roughness varies: `roughness` times the map's first channel (read
        /// linearly; glTF's `sheenRoughnessTexture` is its alpha).
        roughness_map: Option<Texture>,
    },
    /// `weight · a + (1 − weight) · b`.
    Mix {
        /// First BSDF.
        a: Box<BsdfDesc>,
        /// Second BSDF.
        b: Box<BsdfDesc>,
        /// Weight of `a`.
        weight: f64,
        /// Where the weight varies over the surface: `weight` times the texture's luminance
        /// at a point, clamped to `[0, 1]` (Mitsuba's `blendbsdf` with a bitmap weight).
        weight_map: Option<Texture>,
    },
}

impl crate::model::Material {
    /// A material that is only a path-tracer BSDF, with the Whitted and preview coefficients
    /// following it: its diffuse albedo (and `k_d`) as `color` (and `diffuse`), a Phong lobe's
    /// `k_s` and exponent as the highlight, a smooth metal as a mirror of 0.9 (a rough one, α >
    /// 0.05, as a highlight of exponent `2/α² − 2`), glass as transparent
    /// with the BSDF's index; a mix follows its first part.
    pub fn from_bsdf(name: &str, bsdf: BsdfDesc) -> crate::model::Material {
        let mut m = crate::model::Material { name: name.to_string(), ..Default::default() };
        m.follow(&bsdf);
        m.bsdf = Some(bsdf);
        m
    }

    fn follow(&mut self, bsdf: &BsdfDesc) {
        match bsdf {
            BsdfDesc::Lambert { albedo } | BsdfDesc::OrenNayar { albedo, .. } => self.color = albedo.clone(),
            BsdfDesc::CookTorrance { albedo, kd, ks, ior, layered, .. } => {
                // A layered surface's diffuse weight as seen head-on.
                let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
                let kd = if *layered { kd * (1.0 - ks * f0) } else { *kd };
                (self.color, self.diffuse) = (albedo.clone(), kd);
            }
            BsdfDesc::Plastic { albedo, ior, facets, .. } => {
                // The diffuse base as colour, the coat's normal-incidence reflectance as a
                // highlight (as sharp as its roughness) or a faint mirror.
                let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
                self.color = albedo.clone();
                self.diffuse = 1.0 - f0;
                match facets.map(|f| f.alpha_u.max(f.alpha_v)) {
                    Some(alpha) => {
                        self.specular = Vec3::splat(f0);
                        self.shininess = (2.0 / (alpha * alpha) - 2.0).max(1.0);
                    }
                    None => self.mirror = Vec3::splat(f0),
                }
            }
            BsdfDesc::Phong { albedo, kd, ks, exponent } | BsdfDesc::BlinnPhong { albedo, kd, ks, exponent, .. } => {
                (self.color, self.diffuse) = (albedo.clone(), *kd);
                (self.specular, self.shininess) = (Vec3::splat(*ks), *exponent);
            }
            BsdfDesc::Conductor { facets, .. } => {
                self.color = Texture::Solid(Vec3::splat(0.8));
                self.diffuse = 0.0;
                match facets.map(|f| f.alpha_u.max(f.alpha_v)).filter(|&a| a > 0.05) {
                    // Rough: a highlight of the Phong exponent matching the roughness.
                    Some(alpha) => {
                        self.specular = Vec3::splat(0.9);
                        self.shininess = (2.0 / (alpha * alpha) - 2.0).max(1.0);
                    }
                    None => self.mirror = Vec3::splat(0.9),
                }
            }
            BsdfDesc::Dielectric { .. } | BsdfDesc::ThinDielectric { .. } => {
                // A thin sheet bends no ray: the course's transparency through an index of 1.
                let ior = match bsdf {
                    BsdfDesc::Dielectric { ior, .. } => ior.nominal(),
                    _ => 1.0,
                };
                self.color = Texture::Solid(Vec3::splat(0.8));
                self.diffuse = 0.0;
                self.transparency = Vec3::ONE;
                self.ior = ior;
                self.specular = Vec3::ONE;
                self.shininess = 200.0;
            }
            BsdfDesc::MetallicRoughness {
                base, metallic, roughness, ior, specular, multiscatter, anisotropy, ..
            } => {
                // As the importers' material of these factors is followed: its metal where there
                // is metal, else its coating, of colour `base`.
                let lobes = MetalRoughness {
                    ior: *ior,
                    specular: *specular,
                    multiscatter: *multiscatter,
                    anisotropy: *anisotropy,
                    translucency: Translucency::default(),
                };
                let (metal, coating) = metallic_roughness_lobes(Vec3::ONE, *roughness, lobes);
                if *metallic > 0.0 {
                    self.follow(&metal);
                } else {
                    self.follow(&coating);
                    self.color = base.clone();
                }
            }
            BsdfDesc::Mix { a, .. } => self.follow(a),
            BsdfDesc::Coated { base, .. } | BsdfDesc::Sheened { base, .. } => self.follow(base),
        }
    }
}

/// The metal and the coating of [`BsdfDesc::metallic_roughness_at`].
fn metallic_roughness_lobes(base: Rgb, roughness: f64, lobes: MetalRoughness) -> (BsdfDesc, BsdfDesc) {
    let MetalRoughness { ior, specular, multiscatter, anisotropy, translucency } = lobes;
    let alpha = (roughness * roughness).clamp(0.0, 1.0);
    let (along, across) = anisotropy.alphas(alpha);
    let metal = BsdfDesc::Conductor {
        facets: Some(ggx(along, across)),
        eta: eta_from_f0(base),
        k: Vec3::ZERO,
        tint: Vec3::ONE,
        fresnel: FresnelMode::Schlick,
        multiscatter,
    };
    let coating = BsdfDesc::CookTorrance {
        albedo: Texture::Solid(base),
        kd: 1.0 - translucency.factor,
        ks: specular,
        facets: ggx(along.max(0.01), across.max(0.01)),
        ior,
        fresnel: FresnelMode::Exact,
        layered: true,
        transmittance: Texture::Solid(translucency.color * translucency.factor),
    };
    (metal, coating)
}

/// How a metallic–roughness surface's facets stretch along a direction of brushing: the
/// roughness `α_t` along it and `α_b` across it, from the surface's `α` and `strength`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Anisotropy {
    /// 0: isotropic; at most 1.
    pub strength: f64,
    /// The direction of brushing: the tangent (`∂p/∂u`) turned about the normal towards the
    /// bitangent by this angle, in radians.
    pub rotation: f64,
    /// How `strength` stretches the facets.
    pub model: AnisotropyModel,
}

/// The two readings of an anisotropy `s` the importers meet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AnisotropyModel {
    /// glTF's `KHR_materials_anisotropy`: `α_t = α + (1 − α)s²`, `α_b = α`.
    #[default]
    Gltf,
    /// Disney's principled BRDF (Burley 2012; Mitsuba's `principled`, Cycles' Principled
    /// BSDF): `α_t = α/a`, `α_b = α·a` with the aspect `a = √(1 − 0.9s)`.
    Disney,
}

impl Anisotropy {
    /// `(α_t, α_b)` of a surface of roughness `α` (both `α` when isotropic).
    pub fn alphas(&self, alpha: f64) -> (f64, f64) {
        let s = self.strength.clamp(0.0, 1.0);
        if s == 0.0 {
            return (alpha, alpha);
        }
        match self.model {
            AnisotropyModel::Gltf => (alpha + (1.0 - alpha) * s * s, alpha),
            AnisotropyModel::Disney => {
                let aspect = (1.0 - 0.9 * s).sqrt();
                (alpha / aspect, alpha * aspect)
            }
        }
    }

    /// True when the facets are stretched.
    pub fn is_anisotropic(&self) -> bool {
        self.strength > 0.0
    }

    /// The stretch at a point whose `anisotropyTexture` texel is `texel` (linear RGB): the
    /// strength times its blue, the rotation turned further by the direction of its red and
    /// green (`2c − 1` along the tangent and the bitangent; none where that is zero).
    pub fn at_texel(&self, texel: Vec3) -> Anisotropy {
        let (x, y) = (2.0 * texel.x - 1.0, 2.0 * texel.y - 1.0);
        let turn = if x == 0.0 && y == 0.0 { 0.0 } else { y.atan2(x) };
        Anisotropy { strength: self.strength * texel.z.clamp(0.0, 1.0), rotation: self.rotation + turn, ..*self }
    }
}

/// A thin dielectric film over a metallic–roughness surface (glTF's
/// `KHR_materials_iridescence`, Belcour and Barla 2017): its interference colours blended into
/// both lobes' Fresnel factors with weight `factor`.
#[derive(Clone, Debug, PartialEq)]
pub struct Iridescence {
    /// The film's weight in `[0, 1]`, times `factor_map`'s red channel where there is one.
    pub factor: f64,
    /// The film's index of refraction.
    pub ior: f64,
    /// The film's thickness in nanometres where `thickness_map`'s green channel is 0 and where
    /// it is 1 (glTF's minimum and maximum); the second without a map.
    pub thickness: [f64; 2],
    /// The index of refraction above the film (1; a clear coat's over it).
    pub outside: f64,
    /// Where the weight varies (read linearly).
    pub factor_map: Option<Texture>,
    /// Where the thickness varies (read linearly).
    pub thickness_map: Option<Texture>,
}

impl Iridescence {
    /// The film's weight and thickness (nm) at a point whose maps' texels are `factor_texel`
    /// and `thickness_texel` (linear RGB; `None` where there is no map).
    pub fn at(&self, factor_texel: Option<Vec3>, thickness_texel: Option<Vec3>) -> (f64, f64) {
        let weight = self.factor * factor_texel.map_or(1.0, |t| t.x.clamp(0.0, 1.0));
        let [thin, thick] = self.thickness;
        let thickness = thickness_texel.map_or(thick, |t| thin + (thick - thin) * t.y.clamp(0.0, 1.0));
        (weight.clamp(0.0, 1.0), thickness.max(0.0))
    }
}

/// What shapes the metallic–roughness model's lobes besides its colour, metalness and
/// roughness: the coating's index and specular strength, the metal's multiple scattering.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetalRoughness {
    /// The coating's index of refraction.
    pub ior: f64,
    /// The coating's specular strength.
    pub specular: f64,
    /// The metal gives back the light of several facets.
    pub multiscatter: bool,
    /// Its facets' stretch.
    pub anisotropy: Anisotropy,
    /// The coating's diffuse transmission.
    pub translucency: Translucency,
}

/// A thin sheet's diffuse transmission (glTF's `KHR_materials_diffuse_transmission`): the
/// `factor` of the diffuse light that passes through to the other side rather than being
/// reflected, coloured `color` (`(1 − factor)·base` reflected, `factor·color` transmitted).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Translucency {
    /// In `[0, 1]`; 0 for an opaque surface.
    pub factor: f64,
    /// What the passing light keeps, per channel in `[0, 1]`.
    pub color: Rgb,
}

impl Default for Translucency {
    fn default() -> Self {
        Translucency { factor: 0.0, color: Vec3::ONE }
    }
}

/// GGX microfacets with Smith shadowing, `α` clamped away from 0 (where the distribution
/// degenerates) as imported materials have it.
pub fn ggx(alpha_u: f64, alpha_v: f64) -> Microfacets {
    Microfacets {
        distribution: Distribution::TrowbridgeReitz,
        alpha_u: alpha_u.max(1e-3),
        alpha_v: alpha_v.max(1e-3),
        shadowing: Shadowing::Smith,
    }
}

/// The index whose normal-incidence reflectance is `scale` times that of `ior` (at most 0.99;
/// glTF's `specularColorFactor` and texture, by their mean): `ior` itself at a scale of 1.
pub fn ior_scaled(ior: f64, scale: f64) -> f64 {
    if scale == 1.0 {
        return ior;
    }
    let f0 = (((ior - 1.0) / (ior + 1.0)).powi(2) * scale).clamp(0.0, 0.99);
    ((1.0 + f0.sqrt()) / (1.0 - f0.sqrt())).max(1.0)
}

/// The real index `η` (with `κ = 0`) whose normal-incidence reflectance is `f0`.
pub fn eta_from_f0(f0: Rgb) -> Rgb {
    let r = f0.clamp(Vec3::ZERO, Vec3::splat(0.999)).powf(0.5);
    (Vec3::ONE + r) / (Vec3::ONE - r)
}

impl BsdfDesc {
    /// True when some colour of it is a texture, or some map is given (so hits need texture
    /// coordinates): a thin film's maps on glass included.
    pub fn is_textured(&self) -> bool {
        let mut textured = false;
        self.each_texture(&mut |t, map| textured |= map || !matches!(t, Texture::Solid(_)));
        textured
    }

    /// Calls `f` on every texture a point's BSDF is built from, the lobes' within a layer or
    /// mix included; `map` is true for the maps given only when they vary (a metallic–roughness
    /// map, a film's thickness…), false for colours that are always there.
    pub fn each_texture(&self, f: &mut impl FnMut(&Texture, bool)) {
        let maps = |ts: &[&Option<Texture>], f: &mut dyn FnMut(&Texture, bool)| {
            ts.iter().filter_map(|t| t.as_ref()).for_each(|t| f(t, true))
        };
        let film = |i: &Option<Box<Iridescence>>, f: &mut dyn FnMut(&Texture, bool)| {
            if let Some(i) = i {
                maps(&[&i.factor_map, &i.thickness_map], f);
            }
        };
        match self {
            BsdfDesc::Lambert { albedo }
            | BsdfDesc::OrenNayar { albedo, .. }
            | BsdfDesc::Phong { albedo, .. }
            | BsdfDesc::BlinnPhong { albedo, .. }
            | BsdfDesc::Plastic { albedo, .. } => f(albedo, false),
            // The layered form's transmittance is looked up at each point too (`bsdf::build`).
            BsdfDesc::CookTorrance { albedo, transmittance, .. } => {
                f(albedo, false);
                f(transmittance, false);
            }
            BsdfDesc::Mix { a, b, weight_map, .. } => {
                a.each_texture(f);
                b.each_texture(f);
                maps(&[weight_map], f);
            }
            BsdfDesc::Coated { base, weight_map, roughness_map, .. } => {
                base.each_texture(f);
                maps(&[weight_map, roughness_map], f);
            }
            BsdfDesc::Sheened { base, color, roughness_map, .. } => {
                base.each_texture(f);
                f(color, false);
                maps(&[roughness_map], f);
            }
            BsdfDesc::MetallicRoughness {
                base,
                map,
                anisotropy_map,
                iridescence,
                specular_map,
                specular_color_map,
                translucency_map,
                translucency_color_map,
                ..
            } => {
                f(base, false);
                maps(
                    &[map, anisotropy_map, specular_map, specular_color_map, translucency_map, translucency_color_map],
                    f,
                );
                film(iridescence, f);
            }
            BsdfDesc::Dielectric { transmittance, film: glass_film, .. } => {
                f(transmittance, false);
                film(glass_film, f);
            }
            BsdfDesc::Conductor { .. } | BsdfDesc::ThinDielectric { .. } => {}
        }
    }

    /// glTF 2.0's metallic–roughness model at a point of base colour `base`, as the parts of a
    /// mix: a metal whose normal-incidence reflectance is `base` (Schlick's term), its weight
    /// `metallic`, and Cook–Torrance over Lambert (a coating of index `ior`, its specular lobe
    /// of strength `specular`), both on GGX facets of `α = roughness²`. Every point has the same
    /// lobes — a mix even where `metallic` is 0 or 1, facets of `α ≥ 10⁻³` even where
    /// `roughness` is 0 (the coating's `α ≥ 0.01`, as the importers' constant materials) — so a
    /// surface's kind of BSDF never changes.
    pub fn metallic_roughness_at(
        base: Rgb,
        metallic: f64,
        roughness: f64,
        lobes: MetalRoughness,
    ) -> (BsdfDesc, BsdfDesc, f64) {
        let (metal, coating) = metallic_roughness_lobes(base, roughness, lobes);
        (metal, coating, metallic.clamp(0.0, 1.0))
    }

    /// True when some lobe turns with the surface's tangent: Blinn–Phong's scratches, or
    /// microfacets of two roughnesses.
    pub fn is_anisotropic(&self) -> bool {
        let two = |f: &Microfacets| f.alpha_u != f.alpha_v;
        match self {
            BsdfDesc::BlinnPhong { .. } => true,
            BsdfDesc::CookTorrance { facets, .. } => two(facets),
            BsdfDesc::Conductor { facets: Some(f), .. } | BsdfDesc::Dielectric { facets: Some(f), .. } => two(f),
            BsdfDesc::Mix { a, b, .. } => a.is_anisotropic() || b.is_anisotropic(),
            BsdfDesc::Coated { base, facets, .. } => base.is_anisotropic() || two(facets),
            BsdfDesc::Sheened { base, .. } => base.is_anisotropic(),
            BsdfDesc::MetallicRoughness { anisotropy, .. } => anisotropy.is_anisotropic(),
            _ => false,
        }
    }

    /// True when some part of it refracts light into a solid inside (a dielectric: its inside
    /// may absorb, `Material::absorption`; a thin sheet has none).
    pub fn refracts(&self) -> bool {
        match self {
            BsdfDesc::Dielectric { .. } => true,
            BsdfDesc::Mix { a, b, .. } => a.refracts() || b.refracts(),
            BsdfDesc::Coated { base, .. } | BsdfDesc::Sheened { base, .. } => base.refracts(),
            _ => false,
        }
    }

    /// True when some part of it refracts with a wavelength-dependent index.
    pub fn is_dispersive(&self) -> bool {
        match self {
            BsdfDesc::Dielectric { ior, .. } => ior.is_dispersive(),
            BsdfDesc::Mix { a, b, .. } => a.is_dispersive() || b.is_dispersive(),
            BsdfDesc::Coated { base, .. } | BsdfDesc::Sheened { base, .. } => base.is_dispersive(),
            _ => false,
        }
    }
}

/// Complex indices of refraction `(η, κ)` at red, green and blue of common metals (pbrt-v3's
/// RGB values of measured spectra).
pub const METALS: &[(&str, [f64; 3], [f64; 3])] = &[
    ("gold", [0.143119, 0.374957, 1.44248], [3.98316, 2.38572, 1.60322]),
    ("silver", [0.155265, 0.116723, 0.138342], [4.82835, 3.12225, 2.14696]),
    ("copper", [0.200438, 0.924033, 1.10221], [3.91295, 2.45285, 2.14219]),
    ("aluminium", [1.65746, 0.880369, 0.521229], [9.22387, 6.26952, 4.837]),
];

/// Sellmeier coefficients of common glasses (Schott data sheets).
pub const GLASSES: &[(&str, [f64; 3], [f64; 3])] = &[
    ("bk7", [1.03961212, 0.231792344, 1.01046945], [0.00600069867, 0.0200179144, 103.560653]),
    ("sf11", [1.73759695, 0.313747346, 1.89878101], [0.013188707, 0.0623068142, 155.23629]),
    ("fused-silica", [0.6961663, 0.4079426, 0.8974794], [0.0046791483, 0.0135120631, 97.9340025]),
];

/// The complex index `(η, κ)` of a metal of [`METALS`] by name.
pub fn metal(name: &str) -> Option<(Rgb, Rgb)> {
    METALS.iter().find(|m| m.0 == name).map(|m| (Vec3::from_array(m.1), Vec3::from_array(m.2)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use alhazen_math::Vec2;

    fn image(image: usize) -> Texture {
        Texture::Image { image, scale: Vec2::ONE, offset: Vec2::ZERO, rotation: 0.0 }
    }

    fn glass(film: Option<Box<Iridescence>>, transmittance: Texture) -> BsdfDesc {
        BsdfDesc::Dielectric { facets: None, ior: Ior::Constant(1.5), fresnel: FresnelMode::Exact, transmittance, film }
    }

    fn film(factor_map: Option<Texture>, thickness_map: Option<Texture>) -> Option<Box<Iridescence>> {
        Some(Box::new(Iridescence {
            factor: 1.0,
            ior: 1.3,
            thickness: [100.0, 400.0],
            outside: 1.0,
            factor_map,
            thickness_map,
        }))
    }

    /// Glass whose film varies over it, and a layered Cook–Torrance surface whose
    /// transmittance does, are read at each point: their hits need texture coordinates (they
    /// were once taken for uniform, their maps read at `uv = 0` everywhere).
    #[test]
    fn every_map_makes_a_bsdf_textured() {
        let white = Texture::Solid(Vec3::ONE);
        assert!(!glass(None, white.clone()).is_textured());
        assert!(!glass(film(None, None), white.clone()).is_textured());
        assert!(glass(film(Some(image(0)), None), white.clone()).is_textured());
        assert!(glass(film(None, Some(white.clone())), white.clone()).is_textured(), "a map given is read");
        assert!(glass(None, image(1)).is_textured());
        let cook_torrance = |transmittance| BsdfDesc::CookTorrance {
            albedo: Texture::Solid(Vec3::splat(0.5)),
            kd: 1.0,
            ks: 0.5,
            facets: ggx(0.2, 0.2),
            ior: 1.5,
            fresnel: FresnelMode::Exact,
            layered: true,
            transmittance,
        };
        assert!(!cook_torrance(white.clone()).is_textured());
        assert!(cook_torrance(image(2)).is_textured());
    }

    /// Textures within mixes and layers are found, each once, in order.
    #[test]
    fn nested_textures_are_each_visited() {
        let lambert = |k| BsdfDesc::Lambert { albedo: image(k) };
        let coated = BsdfDesc::Coated {
            base: Box::new(lambert(1)),
            weight: 1.0,
            facets: ggx(0.1, 0.1),
            ior: 1.5,
            weight_map: Some(image(2)),
            roughness_map: None,
        };
        let mix =
            BsdfDesc::Mix { a: Box::new(lambert(0)), b: Box::new(coated), weight: 0.5, weight_map: Some(image(3)) };
        let mut seen = vec![];
        mix.each_texture(&mut |t, map| {
            if let Texture::Image { image, .. } = t {
                seen.push((*image, map));
            }
        });
        assert_eq!(seen, [(0, false), (1, false), (2, true), (3, true)]);
    }
}
