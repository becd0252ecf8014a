//! Environment light: the radiance arriving from every direction at infinity, as an
//! equirectangular image (`EnvironmentImage`), and the split-sum model that lights PBR surfaces
//! with it — diffuse from its irradiance as nine spherical-harmonic coefficients, specular from
//! its radiance prefiltered by the GGX lobe times the BRDF's integral over the hemisphere
//! (`brdf_integral`). The GPU prefilters the image once (ml-render's environment module); this
//! module is the CPU reference the image tests compare it with, and makes the built-in sky.
//! It is also the environment's scene section (`SECTION`): a scene file's `[environment]`
//! table and what a request asks of it (`EnvironmentAsk`).

use crate::file_fields;
use crate::files::read_regular;
use crate::scene::Scene;
use crate::scene_section::{Section, Sections};
use crate::section_kind::{AskError, FileSite, RequestSite, SectionError, SectionKind};
use crate::shading::d_ggx;
use crate::shading_model::ShadingModel;
use glam::{Mat3, Vec2, Vec3};
use std::f32::consts::PI;
use std::path::Path;
use std::sync::Arc;

/// Largest environment file read (a 16k × 8k RGBA float EXR is 2 GiB; real ones are 50 MiB).
pub const MAX_ENVIRONMENT_FILE_BYTES: u64 = 1 << 30;
/// Largest environment image side (texels).
pub const MAX_ENVIRONMENT_SIZE: u32 = 8192;
/// The built-in sky's width (its height is half).
pub const SKY_WIDTH: u32 = 512;

/// Linear radiance from every direction: row 0 looks up (+Y), column 0 looks along +Z...
/// (`equirect_uv` is the mapping), stored as RGB floats row by row.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentImage {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 3]>,
}

/// An environment as a scene holds it: the image (shared: scenes are cloned) and how it is
/// applied.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    pub image: Arc<EnvironmentImage>,
    /// Radiance multiplier.
    pub intensity: f32,
    /// Turn of the environment about +Y, in radians (counter-clockwise seen from above).
    pub rotation: f32,
    /// Shown behind the scene where no surface is, unless the render asks otherwise (a scene
    /// file's `[environment] background = true`).
    pub background: bool,
}

impl Environment {
    /// The built-in sky at unit intensity, unrotated.
    pub fn sky() -> Environment {
        Environment { image: Arc::new(EnvironmentImage::sky(SKY_WIDTH)), intensity: 1.0, rotation: 0.0, background: false }
    }

    /// World direction → the image's own (the environment turned by `rotation` about +Y).
    pub fn to_image(&self) -> Mat3 {
        Mat3::from_rotation_y(-self.rotation)
    }
}

/// Which environment lights a scene (the pbr model).
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentSource {
    /// None: the constant ambient term.
    Off,
    /// The built-in sky (`EnvironmentImage::sky`).
    Sky,
    /// An equirectangular Radiance .hdr or OpenEXR file.
    File(std::path::PathBuf),
}

impl EnvironmentSource {
    /// `none`, `sky`, or a file's path.
    pub fn parse(text: &str) -> EnvironmentSource {
        match text {
            "none" => EnvironmentSource::Off,
            "sky" => EnvironmentSource::Sky,
            path => EnvironmentSource::File(path.into()),
        }
    }

    /// The environment at unit intensity, unrotated (None: off).
    pub fn load(&self) -> Result<Option<Environment>, EnvironmentError> {
        Ok(match self {
            EnvironmentSource::Off => None,
            EnvironmentSource::Sky => Some(Environment::sky()),
            EnvironmentSource::File(path) => {
                Some(Environment { image: Arc::new(EnvironmentImage::load(path)?), intensity: 1.0, rotation: 0.0, background: false })
            }
        })
    }
}

/// The environment as a scene's section (`section_kind`): a scene file's `[environment]`
/// table, the request's `EnvironmentAsk`.
pub const SECTION: SectionKind =
    SectionKind { table: "environment", read: read_table, replaces_file, unlit_file: sky_for_unlit_file, apply: apply_ask };

/// What a request asks of the environment (the command line's `--environment`,
/// `--environment-intensity` and `--environment-rotation`; the window's panel).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EnvironmentAsk {
    /// The environment light: None: a file's own, else the built-in sky for a file without
    /// lights of its own (the default rig lights it too), else none.
    pub source: Option<EnvironmentSource>,
    /// Its intensity and turn about +Y in degrees, where given (else its own: 1 and 0 unless
    /// a scene file says).
    pub intensity: Option<f32>,
    pub rotation_deg: Option<f32>,
}

/// A scene file's `[environment]` table.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct FileEnvironment {
    /// An equirectangular .hdr or .exr file (relative to the scene file's folder), "sky" or
    /// "none".
    file: String,
    intensity: Option<f32>,
    rotation_deg: Option<f32>,
    /// Shown behind the scene (else the render's background colour).
    background: Option<bool>,
}

/// The file's `[environment]`: its image (a path relative to the scene file's folder; not
/// read where the request replaces it), intensity and turn.
fn read_table(table: toml::de::ValueDeserializer<'_>, site: &FileSite) -> Result<Option<Box<dyn Section>>, SectionError> {
    let e = <FileEnvironment as serde::Deserialize>::deserialize(table)?;
    let intensity = e.intensity.map(|i| file_fields::intensity("[environment] intensity", i)).transpose()?;
    let what = "[environment] rotation_deg";
    let range = -MAX_ENVIRONMENT_ROTATION_DEG..=MAX_ENVIRONMENT_ROTATION_DEG;
    let rotation = e.rotation_deg.map(|r| file_fields::within(what, file_fields::finite(what, r)?, range)).transpose()?;
    let source = match EnvironmentSource::parse(&e.file) {
        EnvironmentSource::File(path) => EnvironmentSource::File(site.folder.ok_or(SectionError::NoFolder)?.join(path)),
        other => other,
    };
    if site.replaced {
        return Ok(None);
    }
    let Some(mut env) = source.load().map_err(|err| SectionError::Unusable(err.to_string()))? else { return Ok(None) };
    env.intensity = intensity.unwrap_or(env.intensity);
    env.rotation = rotation.map_or(env.rotation, f32::to_radians);
    env.background = e.background.unwrap_or(false);
    Ok(Some(Box::new(env)))
}

/// An environment asked for replaces the file's: its image is not read.
fn replaces_file(asks: &Sections) -> bool {
    asks.get::<EnvironmentAsk>().is_some_and(|a| a.source.is_some())
}

/// A pbr model without lights of its own looks as it does in a glTF viewer: under a sky.
fn sky_for_unlit_file(asks: &Sections, scene: &mut Scene, site: &RequestSite) {
    if site.shading == ShadingModel::Pbr && !replaces_file(asks) && scene.sections.get::<Environment>().is_none() {
        scene.sections.set(Some(Environment::sky()));
    }
}

/// The environment asked for, at the intensity and turn asked for.
fn apply_ask(asks: &Sections, scene: &mut Scene, _site: &RequestSite) -> Result<(), AskError> {
    let Some(ask) = asks.get::<EnvironmentAsk>() else { return Ok(()) };
    if let Some(source) = &ask.source {
        scene.sections.set(source.load()?);
    }
    if let Some(env) = scene.sections.get_mut::<Environment>() {
        env.intensity = ask.intensity.unwrap_or(env.intensity);
        env.rotation = ask.rotation_deg.map_or(env.rotation, f32::to_radians);
    }
    Ok(())
}

/// Largest environment intensity (the lights' own cap).
pub const MAX_ENVIRONMENT_INTENSITY: f32 = crate::limits::MAX_INTENSITY;
/// Largest turn of an environment, in degrees either way.
pub const MAX_ENVIRONMENT_ROTATION_DEG: f32 = 36_000.0;

/// An intensity as given (text): finite, 0 to MAX_ENVIRONMENT_INTENSITY.
pub fn parse_intensity(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && (0.0..=MAX_ENVIRONMENT_INTENSITY).contains(&v) => Ok(v),
        _ => Err(format!("environment intensity '{text}': expected a number from 0 to {MAX_ENVIRONMENT_INTENSITY}")),
    }
}

/// A turn as given (text, degrees): finite, within ±MAX_ENVIRONMENT_ROTATION_DEG.
pub fn parse_rotation_deg(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v.abs() <= MAX_ENVIRONMENT_ROTATION_DEG => Ok(v),
        _ => Err(format!(
            "environment rotation '{text}': expected degrees from -{MAX_ENVIRONMENT_ROTATION_DEG} to {MAX_ENVIRONMENT_ROTATION_DEG}"
        )),
    }
}

/// Why an environment file could not be used.
#[derive(Debug, thiserror::Error)]
pub enum EnvironmentError {
    #[error("cannot read environment '{path}': {source}")]
    Read { path: String, source: crate::files::ReadError },
    #[error("environment '{path}' is not an image this reads (Radiance .hdr or OpenEXR): {reason}")]
    Decode { path: String, reason: String },
    #[error(
        "environment '{path}' is {width}x{height}: an equirectangular image is twice as wide as high, at most {MAX_ENVIRONMENT_SIZE} wide"
    )]
    Shape { path: String, width: u32, height: u32 },
    #[error("environment '{path}' holds a value that is not a finite radiance >= 0 (texel {texel})")]
    Value { path: String, texel: usize },
}

/// Unit direction → equirectangular coordinates in [0, 1]²: u turns with the azimuth about +Y
/// (u = 0.5 looks along −Z), v = 0 looks up. The shaders' `equirect_uv` is the same formula.
pub fn equirect_uv(d: Vec3) -> Vec2 {
    Vec2::new(0.5 + d.x.atan2(-d.z) / (2.0 * PI), d.y.clamp(-1.0, 1.0).acos() / PI)
}

/// The direction through equirectangular coordinates `uv` (`equirect_uv`'s inverse).
pub fn equirect_direction(uv: Vec2) -> Vec3 {
    let phi = (uv.x - 0.5) * 2.0 * PI;
    let theta = uv.y * PI;
    Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos())
}

impl EnvironmentImage {
    /// The built-in sky, `width` × `width / 2`: a blue zenith fading to a bright horizon, a
    /// warm sun glow high in the south-west, a dark ground below a soft horizon. Smooth
    /// everywhere (no disc sharper than a few degrees), so any prefilter resolution shows it
    /// without aliasing.
    pub fn sky(width: u32) -> EnvironmentImage {
        let height = (width / 2).max(1);
        let mut texels = Vec::with_capacity((width * height) as usize);
        for y in 0..height {
            for x in 0..width {
                let uv = Vec2::new((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32);
                texels.push(sky_radiance(equirect_direction(uv)).to_array());
            }
        }
        EnvironmentImage { width, height, texels }
    }

    /// An equirectangular Radiance .hdr or OpenEXR file (the format found from its bytes);
    /// a regular file of at most MAX_ENVIRONMENT_FILE_BYTES, 2:1, every value finite and ≥ 0.
    pub fn load(path: &Path) -> Result<EnvironmentImage, EnvironmentError> {
        let name = path.display().to_string();
        let bytes =
            read_regular(path, MAX_ENVIRONMENT_FILE_BYTES).map_err(|source| EnvironmentError::Read { path: name.clone(), source })?;
        let decode_error = |reason: String| EnvironmentError::Decode { path: name.clone(), reason };
        let mut reader =
            image::ImageReader::new(std::io::Cursor::new(&bytes)).with_guessed_format().map_err(|e| decode_error(e.to_string()))?;
        match reader.format() {
            Some(image::ImageFormat::Hdr | image::ImageFormat::OpenExr) => {}
            Some(other) => return Err(decode_error(format!("it is {other:?}"))),
            None => return Err(decode_error("its format is none this knows".into())),
        }
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_ENVIRONMENT_SIZE);
        limits.max_image_height = Some(MAX_ENVIRONMENT_SIZE);
        limits.max_alloc = Some(4 << 30);
        reader.limits(limits);
        let decoded = crate::image_decode::guarded_decode(|| reader.decode())
            .ok_or_else(|| decode_error("its decoder stopped on malformed data".into()))?
            .map_err(|e| decode_error(e.to_string()))?
            .into_rgb32f();
        let (width, height) = decoded.dimensions();
        if width != 2 * height || width > MAX_ENVIRONMENT_SIZE {
            return Err(EnvironmentError::Shape { path: name, width, height });
        }
        let texels: Vec<[f32; 3]> = decoded.pixels().map(|p| p.0).collect();
        if let Some(texel) = texels.iter().position(|t| t.iter().any(|c| !(c.is_finite() && *c >= 0.0))) {
            return Err(EnvironmentError::Value { path: name, texel });
        }
        Ok(EnvironmentImage { width, height, texels })
    }

    /// Texel (x, y), x wrapping round and y clamped.
    fn texel(&self, x: i64, y: i64) -> Vec3 {
        let x = x.rem_euclid(i64::from(self.width)) as usize;
        let y = y.clamp(0, i64::from(self.height) - 1) as usize;
        Vec3::from(self.texels[y * self.width as usize + x])
    }

    /// Radiance from direction `d` (in the image's frame), filtered bilinearly.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        let uv = equirect_uv(d);
        let (fx, fy) = (uv.x * self.width as f32 - 0.5, uv.y * self.height as f32 - 0.5);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), tx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), tx);
        top.lerp(bottom, ty)
    }

    /// Each texel's direction, radiance and solid angle.
    fn texels_with_solid_angle(&self) -> impl Iterator<Item = (Vec3, Vec3, f32)> + '_ {
        let (w, h) = (self.width as f32, self.height as f32);
        self.texels.iter().enumerate().map(move |(i, t)| {
            let (x, y) = ((i % self.width as usize) as f32, (i / self.width as usize) as f32);
            let uv = Vec2::new((x + 0.5) / w, (y + 0.5) / h);
            let solid_angle = (2.0 * PI / w) * (PI / h) * (uv.y * PI).sin();
            (equirect_direction(uv), Vec3::from(*t), solid_angle)
        })
    }
}

/// The built-in sky's radiance towards `d`.
pub fn sky_radiance(d: Vec3) -> Vec3 {
    let zenith = Vec3::new(0.18, 0.36, 0.85);
    let horizon = Vec3::new(0.95, 0.97, 1.0);
    let up = d.y.max(0.0);
    let sky = horizon.lerp(zenith, up.powf(0.5));
    let sun_direction = Vec3::new(-0.5, 0.6, 0.62).normalize();
    // A glow about 8 degrees wide: bright, but smooth at any resolution.
    let glow = Vec3::new(1.0, 0.85, 0.65) * 6.0 * ((d.dot(sun_direction) - 1.0) / 0.02).exp();
    let ground = Vec3::new(0.16, 0.14, 0.12) * (1.0 - 0.4 * (-d.y).clamp(0.0, 1.0));
    let t = smoothstep(-0.04, 0.04, d.y);
    ground.lerp(sky + glow, t)
}

fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The nine real spherical harmonics of band 0–2 at unit direction `d` (the shaders'
/// `sh9_basis`).
pub fn sh9_basis(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        0.282_095,
        0.488_603 * y,
        0.488_603 * z,
        0.488_603 * x,
        1.092_548 * x * y,
        1.092_548 * y * z,
        0.315_392 * (3.0 * z * z - 1.0),
        1.092_548 * x * z,
        0.546_274 * (x * x - y * y),
    ]
}

/// The convolution by the clamped cosine over π, per band (Ramamoorthi and Hanrahan 2001:
/// Â₀ = π, Â₁ = 2π/3, Â₂ = π/4): applied to the radiance's coefficients, their sum at a normal
/// is the irradiance over π — what a white Lambert surface reflects.
pub const SH9_LAMBERT: [f32; 9] = [1.0, 2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0, 0.25, 0.25, 0.25, 0.25, 0.25];

/// The coefficients whose sum at normal n (`diffuse_sh9`) is the light a white Lambert surface
/// facing n reflects: the radiance projected on `sh9_basis` over the sphere, times SH9_LAMBERT.
pub fn diffuse_sh9(image: &EnvironmentImage) -> [Vec3; 9] {
    let mut sum = [[0f64; 3]; 9];
    for (d, radiance, solid_angle) in image.texels_with_solid_angle() {
        for (s, y) in sum.iter_mut().zip(sh9_basis(d)) {
            for c in 0..3 {
                s[c] += f64::from(radiance[c] * y * solid_angle);
            }
        }
    }
    let mut out = [Vec3::ZERO; 9];
    for i in 0..9 {
        out[i] = Vec3::new(sum[i][0] as f32, sum[i][1] as f32, sum[i][2] as f32) * SH9_LAMBERT[i];
    }
    out
}

/// What a white Lambert surface facing `n` reflects under coefficients `sh` (`diffuse_sh9`).
pub fn sh9_diffuse_at(sh: &[Vec3; 9], n: Vec3) -> Vec3 {
    sh.iter().zip(sh9_basis(n)).map(|(c, y)| *c * y).sum::<Vec3>().max(Vec3::ZERO)
}

/// The radiance reflected towards R by a GGX lobe of `roughness` about R (the split sum's first
/// factor, with n = v = R): the lobe-weighted mean Σ L(l)(n·l)D(h) / Σ (n·l)D(h) over the
/// image's texels, h halfway between R and l. Roughness 0 reads the radiance at R.
pub fn prefiltered_radiance(image: &EnvironmentImage, r: Vec3, roughness: f32) -> Vec3 {
    if roughness == 0.0 {
        return image.radiance(r);
    }
    let (mut sum, mut weight) = (glam::DVec3::ZERO, 0f64);
    for (l, radiance, solid_angle) in image.texels_with_solid_angle() {
        let n_dot_l = r.dot(l);
        if n_dot_l <= 0.0 {
            continue;
        }
        let h = (r + l).normalize();
        let w = f64::from(n_dot_l * d_ggx(r.dot(h), roughness) * solid_angle);
        sum += radiance.as_dvec3() * w;
        weight += w;
    }
    if weight > 0.0 {
        (sum / weight).as_vec3()
    } else {
        image.radiance(r)
    }
}

/// The Hammersley point i of n: (i/n, radical inverse of i in base 2). The shaders' own.
pub fn hammersley(i: u32, n: u32) -> Vec2 {
    Vec2::new(i as f32 / n as f32, i.reverse_bits() as f32 * 2.328_306_4e-10)
}

/// A GGX half vector about +Z for roughness `roughness` from the uniform point `xi`.
pub fn ggx_half_vector(xi: Vec2, roughness: f32) -> Vec3 {
    let a = roughness * roughness;
    let phi = 2.0 * PI * xi.x;
    let cos_theta = ((1.0 - xi.y) / (1.0 + (a * a - 1.0) * xi.y)).sqrt();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// The BRDF's hemispherical integral split as F₀·A + B (Karis 2013): GGX importance-sampled
/// with `samples` Hammersley points, Smith–Schlick visibility with k = α/2 (the image-based
/// form), for n·v and roughness.
pub fn brdf_integral(n_dot_v: f32, roughness: f32, samples: u32) -> Vec2 {
    let n_dot_v = n_dot_v.max(1e-4);
    let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
    let k = roughness * roughness / 2.0;
    let g1 = |c: f32| c / (c * (1.0 - k) + k);
    let (mut a, mut b) = (0f64, 0f64);
    for i in 0..samples {
        let h = ggx_half_vector(hammersley(i, samples), roughness);
        let l = 2.0 * v.dot(h) * h - v;
        let (n_dot_l, n_dot_h, v_dot_h) = (l.z, h.z.max(0.0), v.dot(h).max(0.0));
        if n_dot_l > 0.0 {
            let visibility = g1(n_dot_l) * g1(n_dot_v) * v_dot_h / (n_dot_h * n_dot_v);
            let fc = (1.0 - v_dot_h).powi(5);
            a += f64::from((1.0 - fc) * visibility);
            b += f64::from(fc * visibility);
        }
    }
    Vec2::new((a / f64::from(samples)) as f32, (b / f64::from(samples)) as f32)
}

/// What glTF's Fresnel term takes from a diffuse layer seen at `n_dot_v` under light from
/// every direction: its weight 1 − F(v·h) averaged over cosine-distributed light directions
/// is 1 − (F₀ + (F₉₀ − F₀)·c), c the mean of Schlick's (1 − v·h)⁵ returned here (Hammersley
/// points, `samples` of them; the shaders' BRDF table holds it beside A and B): almost 0 seen
/// head-on (v·h ≥ cos 45° there), 0.028 at a grazing view.
pub fn diffuse_fresnel_weight(n_dot_v: f32, samples: u32) -> f32 {
    let n_dot_v = n_dot_v.max(1e-4);
    let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
    let mut c = 0f64;
    for i in 0..samples {
        let xi = hammersley(i, samples);
        let (phi, cos_theta, sin_theta) = (2.0 * PI * xi.x, (1.0 - xi.y).sqrt(), xi.y.sqrt());
        let l = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
        c += f64::from((1.0 - v.dot((v + l).normalize()).clamp(0.0, 1.0)).powi(5));
    }
    (c / f64::from(samples)) as f32
}

/// Where a GGX lobe of `roughness` about the reflection `r` gathers most of its light: the
/// rougher, the nearer the normal `n` (Lagarde and de Rousiers 2014, as Filament writes it).
pub fn dominant_direction(n: Vec3, r: Vec3, roughness: f32) -> Vec3 {
    r.lerp(n, roughness * roughness).normalize()
}

/// The split-sum lighting of a PBR surface by `env`: diffuse albedo·(1 − metallic) under the
/// irradiance coefficients `sh` (of the image, `diffuse_sh9`) times `occlusion`, less what the
/// dielectric's Fresnel term reflects (`diffuse_fresnel_weight`), plus the radiance prefiltered
/// towards the lobe's dominant direction times (F₀·A + B), times the environment's intensity.
/// `n`, `v` unit (normal, towards the eye), in the world.
pub fn environment_light(
    env: &Environment,
    sh: &[Vec3; 9],
    (n, v): (Vec3, Vec3),
    albedo: Vec3,
    (roughness, metallic, occlusion): (f32, f32, f32),
) -> Vec3 {
    let to_image = env.to_image();
    let n_dot_v = n.dot(v).clamp(0.0, 1.0);
    let r = (2.0 * n.dot(v) * n - v).normalize();
    let reflected = 0.04 + 0.96 * diffuse_fresnel_weight(n_dot_v, 512);
    let diffuse = albedo * (1.0 - metallic) * (1.0 - reflected) * sh9_diffuse_at(sh, to_image * n) * occlusion;
    let f0 = Vec3::splat(0.04).lerp(albedo, metallic);
    let ab = brdf_integral(n_dot_v, roughness, 512);
    let specular =
        prefiltered_radiance(&env.image, to_image * dominant_direction(n, r, roughness), roughness) * (f0 * ab.x + Vec3::splat(ab.y));
    (diffuse + specular * specular_occlusion(n_dot_v, occlusion, roughness)) * env.intensity
}

/// How much of the environment's specular light an ambient-occluded point still sees
/// (Lagarde and de Rousiers 2014): 1 unoccluded, less where the lobe is wide and the point
/// occluded.
pub fn specular_occlusion(n_dot_v: f32, occlusion: f32, roughness: f32) -> f32 {
    if occlusion >= 1.0 {
        return 1.0;
    }
    ((n_dot_v + occlusion).powf((-16.0 * roughness - 1.0).exp2()) - 1.0 + occlusion).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equirect_mapping_round_trips() {
        for d in [Vec3::Y, -Vec3::Z, Vec3::X, Vec3::new(0.3, -0.5, 0.8).normalize(), Vec3::new(-0.7, 0.1, -0.2).normalize()] {
            let back = equirect_direction(equirect_uv(d));
            assert!((back - d).length() < 1e-5, "{d} -> {back}");
        }
        assert!((equirect_uv(-Vec3::Z) - Vec2::new(0.5, 0.5)).length() < 1e-6);
    }

    #[test]
    fn a_constant_environment_lights_a_lambert_surface_with_its_radiance() {
        let image = EnvironmentImage { width: 256, height: 128, texels: vec![[0.5, 1.0, 2.0]; 256 * 128] };
        let sh = diffuse_sh9(&image);
        for n in [Vec3::Y, Vec3::new(0.6, -0.3, 0.74).normalize()] {
            let d = sh9_diffuse_at(&sh, n);
            assert!((d - Vec3::new(0.5, 1.0, 2.0)).abs().max_element() < 2e-3, "{d}");
        }
        // Any lobe over a constant environment is that constant.
        let p = prefiltered_radiance(&image, Vec3::X, 0.6);
        assert!((p - Vec3::new(0.5, 1.0, 2.0)).abs().max_element() < 1e-4, "{p}");
    }

    #[test]
    fn half_an_environment_lights_the_facing_side_by_its_cosine_lobe() {
        // Radiance 1 from above the horizon only: a surface facing up sees 1, facing down 0,
        // a vertical one 1/2 (exactly; SH9 holds it to within a few hundredths).
        let image = EnvironmentImage::sky(64);
        let upper =
            EnvironmentImage { texels: (0..image.texels.len()).map(|i| if i / 64 < 16 { [1.0; 3] } else { [0.0; 3] }).collect(), ..image };
        let sh = diffuse_sh9(&upper);
        assert!((sh9_diffuse_at(&sh, Vec3::Y).x - 1.0).abs() < 0.08);
        assert!(sh9_diffuse_at(&sh, -Vec3::Y).x < 0.08);
        assert!((sh9_diffuse_at(&sh, Vec3::X).x - 0.5).abs() < 0.02);
    }

    #[test]
    fn the_diffuse_fresnel_weight_grows_from_head_on_to_grazing() {
        // Head-on, v·h = cos(θ/2) for light at θ: ∫(1 − cos(θ/2))⁵ 2 cos θ sin θ dθ = 8.19e-5
        // (numerically); at a grazing view 0.0282 (a Monte Carlo estimate of 400,000 points).
        let head_on = diffuse_fresnel_weight(1.0, 4096);
        assert!((head_on - 8.19e-5).abs() < 1e-5, "{head_on}");
        let grazing = diffuse_fresnel_weight(0.0, 4096);
        assert!((grazing - 0.0282).abs() < 5e-4, "{grazing}");
        let mut last = head_on;
        for i in (0..10).rev() {
            let c = diffuse_fresnel_weight(i as f32 / 10.0, 1024);
            assert!(c >= last - 1e-3, "{i}: {c} after {last}");
            last = c;
        }
    }

    #[test]
    fn the_brdf_integral_holds_its_known_values() {
        // Smooth: all of F₀ reflected at normal view (A = 1, B = 0), and Fresnel's rise
        // towards grazing views in B; a rough surface loses much; none reflects more than
        // comes in.
        let smooth = brdf_integral(1.0, 0.0, 256);
        assert!((smooth - Vec2::new(1.0, 0.0)).length() < 1e-3, "{smooth}");
        assert!(brdf_integral(0.1, 0.1, 1024).y > brdf_integral(0.9, 0.1, 1024).y + 0.1);
        let rough = brdf_integral(0.5, 1.0, 1024);
        assert!(rough.x > 0.3 && rough.x < 0.6 && rough.y > 0.0 && rough.y < 0.02, "{rough}");
        for (i, j) in (0..=10).flat_map(|i| (0..=10).map(move |j| (i, j))) {
            let ab = brdf_integral(i as f32 / 10.0, j as f32 / 10.0, 256);
            assert!(ab.min_element() >= 0.0 && ab.x + ab.y <= 1.0 + 1e-3, "{i} {j}: {ab}");
        }
    }

    #[test]
    fn the_sky_is_brighter_above_than_below() {
        let sky = EnvironmentImage::sky(64);
        assert!(sky.radiance(Vec3::Y).y > 4.0 * sky.radiance(-Vec3::Y).y);
        assert!(sky.texels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0));
    }

    #[test]
    fn openexr_and_radiance_files_load_their_values() {
        let dir = crate::files::hostile::folder("environment-valid");
        // 8×4 texels: zero, below one, far above one (a sun), distinct per channel.
        let values: Vec<f32> = (0..8 * 4 * 3).map(|i| if i % 7 == 0 { 0.0 } else { (i as f32 * 0.37).powi(3) / 10.0 }).collect();
        let image = image::Rgb32FImage::from_raw(8, 4, values.clone()).expect("sized");
        let exr = dir.join("sky.exr");
        image::DynamicImage::ImageRgb32F(image.clone()).save_with_format(&exr, image::ImageFormat::OpenExr).expect("EXR written");
        let loaded = EnvironmentImage::load(&exr).expect("a valid EXR");
        assert_eq!((loaded.width, loaded.height), (8, 4));
        assert_eq!(loaded.texels.iter().flatten().copied().collect::<Vec<f32>>(), values, "EXR keeps 32-bit floats exactly");
        // Radiance's shared exponent keeps 8 bits of mantissa: within 1 % of the largest channel.
        let hdr = dir.join("sky.hdr");
        image::DynamicImage::ImageRgb32F(image).save_with_format(&hdr, image::ImageFormat::Hdr).expect("HDR written");
        let loaded = EnvironmentImage::load(&hdr).expect("a valid .hdr");
        assert_eq!((loaded.width, loaded.height), (8, 4));
        for (texel, want) in loaded.texels.iter().zip(values.chunks(3)) {
            let largest = want.iter().copied().fold(0.0f32, f32::max);
            for (got, want) in texel.iter().zip(want) {
                assert!((got - want).abs() <= 0.01 * largest + 1e-6, "{texel:?} against {want}");
            }
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn files_that_are_not_environments_are_refused_in_one_line() {
        let dir = crate::files::hostile::folder("environment");
        let png = dir.join("x.hdr");
        crate::files::write_png(&png, &[0u8; 16], (2, 2)).expect("written");
        let e = EnvironmentImage::load(&png).expect_err("a PNG").to_string();
        assert!(e.contains("is not an image this reads") && !e.contains('\n'), "{e}");
        let garbage = dir.join("y.exr");
        std::fs::write(&garbage, b"\x76\x2f\x31\x01 and then nothing").expect("written");
        let e = EnvironmentImage::load(&garbage).expect_err("a broken EXR").to_string();
        assert!(e.starts_with("environment '") && !e.contains('\n'), "{e}");
        let e = EnvironmentImage::load(&dir).expect_err("a folder").to_string();
        assert!(e.contains("cannot read environment"), "{e}");
    }
}
