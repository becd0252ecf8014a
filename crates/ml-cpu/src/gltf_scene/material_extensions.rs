//! glTF's PBR material extensions read into `MaterialLobes`: KHR_materials_ior,
//! KHR_materials_specular, KHR_materials_clearcoat, KHR_materials_sheen,
//! KHR_materials_unlit, KHR_materials_transmission and KHR_materials_volume — their factors,
//! each checked against its extension's range, and the textures they name (`LobeTextureRefs`,
//! which the loader reads into the object's texture slots). The volume's thickness is in the
//! mesh's units; the loader scales it to the world's per object (`MaterialLobes::thickness`).

use super::{uv_affine, GltfError, MaterialName, Texels};
use crate::material_lobes::MaterialLobes;
use glam::{Affine2, Vec2, Vec3};
use serde_json::Value;

/// The extensions this module reads.
pub(super) const EXTENSIONS: [&str; 7] = [
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_unlit",
    "KHR_materials_transmission",
    "KHR_materials_volume",
];

/// Largest index of refraction we take (diamond is 2.42; 0 means a mirror-like F₀ of 1).
pub const MAX_IOR: f32 = 100.0;

/// A texture an extension names (its textureInfo): the glTF texture, its texture coordinates'
/// set, its KHR_texture_transform and (a normal texture's) scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TextureRef {
    pub index: usize,
    pub tex_coord: u32,
    pub transform: Affine2,
    pub scale: f32,
}

/// The extensions' textures in the object's slot order (`ObjectTextures::slots` from
/// FIRST_LOBE_SLOT): the field that names each in its extension, what the loader calls it,
/// and how its texels are read (colours sRGB, the clear coat's normal map unit normals).
pub(super) const LOBE_TEXTURE_FIELDS: [(&str, &str, Texels); 9] = [
    ("clearcoatTexture", "clearcoat", Texels::Data),
    ("clearcoatRoughnessTexture", "clearcoat roughness", Texels::Data),
    (CLEARCOAT_NORMAL_FIELD, "clearcoat normal", Texels::UnitNormals),
    ("sheenColorTexture", "sheen colour", Texels::Colour),
    ("sheenRoughnessTexture", "sheen roughness", Texels::Data),
    ("specularTexture", "specular", Texels::Data),
    ("specularColorTexture", "specular colour", Texels::Colour),
    ("transmissionTexture", "transmission", Texels::Data),
    ("thicknessTexture", "thickness", Texels::Data),
];

/// The clear coat's normal map, whose scale its lobes keep.
const CLEARCOAT_NORMAL_FIELD: &str = "clearcoatNormalTexture";

/// The textures a material's extensions name, in LOBE_TEXTURE_FIELDS' order.
pub(super) type LobeTextureRefs = [Option<TextureRef>; LOBE_TEXTURE_FIELDS.len()];

/// The lobes of material `m` and the textures its extensions name, in a file of `textures`
/// textures.
pub(super) fn material_lobes(m: &gltf::Material, textures: usize) -> Result<(MaterialLobes, LobeTextureRefs), GltfError> {
    let material = MaterialName(m.index());
    let mut lobes = MaterialLobes::default();
    let mut refs: LobeTextureRefs = [None; LOBE_TEXTURE_FIELDS.len()];
    let read = Reader { material, textures };
    if let Some(ext) = m.extension_value("KHR_materials_ior") {
        lobes.ior = read.number(ext, "ior", lobes.ior, 0.0..=MAX_IOR)?;
        if lobes.ior > 0.0 && lobes.ior < 1.0 {
            return Err(GltfError::Ior { material, value: lobes.ior });
        }
    }
    if let Some(ext) = m.extension_value("KHR_materials_specular") {
        lobes.specular = read.number(ext, "specularFactor", 1.0, 0.0..=1.0)?;
        lobes.specular_color = read.color(ext, "specularColorFactor", Vec3::ONE, 0.0..=f32::MAX)?;
        read.textures(ext, &mut refs)?;
    }
    if let Some(ext) = m.extension_value("KHR_materials_clearcoat") {
        lobes.clearcoat = read.number(ext, "clearcoatFactor", 0.0, 0.0..=1.0)?;
        lobes.clearcoat_roughness = read.number(ext, "clearcoatRoughnessFactor", 0.0, 0.0..=1.0)?;
        read.textures(ext, &mut refs)?;
        let normal = LOBE_TEXTURE_FIELDS.iter().position(|(field, ..)| *field == CLEARCOAT_NORMAL_FIELD);
        lobes.clearcoat_normal_scale = normal.and_then(|i| refs[i]).map_or(1.0, |t| t.scale);
    }
    if let Some(ext) = m.extension_value("KHR_materials_sheen") {
        lobes.sheen_color = read.color(ext, "sheenColorFactor", Vec3::ZERO, 0.0..=1.0)?;
        lobes.sheen_roughness = read.number(ext, "sheenRoughnessFactor", 0.0, 0.0..=1.0)?;
        read.textures(ext, &mut refs)?;
    }
    if let Some(ext) = m.extension_value("KHR_materials_transmission") {
        lobes.transmission = read.number(ext, "transmissionFactor", 0.0, 0.0..=1.0)?;
        read.textures(ext, &mut refs)?;
    }
    if let Some(ext) = m.extension_value("KHR_materials_volume") {
        lobes.thickness = read.number(ext, "thicknessFactor", 0.0, 0.0..=f32::MAX)?;
        lobes.attenuation_distance = read.number(ext, "attenuationDistance", f32::INFINITY, f32::MIN_POSITIVE..=f32::INFINITY)?;
        lobes.attenuation_color = read.color(ext, "attenuationColor", Vec3::ONE, 0.0..=1.0)?;
        read.textures(ext, &mut refs)?;
    }
    lobes.unlit = m.extension_value("KHR_materials_unlit").is_some();
    Ok((lobes, refs))
}

struct Reader {
    material: MaterialName,
    /// The file's textures.
    textures: usize,
}

impl Reader {
    /// Field `name` of extension object `ext`: `default` where absent, else a number in `range`.
    fn number(&self, ext: &Value, name: &'static str, default: f32, range: std::ops::RangeInclusive<f32>) -> Result<f32, GltfError> {
        let Some(v) = ext.get(name) else { return Ok(default) };
        let value = v.as_f64().map_or(f32::NAN, |x| x as f32);
        if !range.contains(&value) {
            return Err(GltfError::ExtensionFactor { material: self.material, field: name, value: v.to_string(), range });
        }
        Ok(value)
    }

    /// An RGB field: three numbers, each in `range`.
    fn color(&self, ext: &Value, name: &'static str, default: Vec3, range: std::ops::RangeInclusive<f32>) -> Result<Vec3, GltfError> {
        let Some(v) = ext.get(name) else { return Ok(default) };
        let parts: Option<Vec<f32>> =
            v.as_array().filter(|a| a.len() == 3).map(|a| a.iter().map(|x| x.as_f64().map_or(f32::NAN, |x| x as f32)).collect());
        match parts {
            Some(p) if p.iter().all(|x| range.contains(x)) => Ok(Vec3::new(p[0], p[1], p[2])),
            _ => Err(GltfError::ExtensionFactor { material: self.material, field: name, value: v.to_string(), range }),
        }
    }

    /// Each texture of LOBE_TEXTURE_FIELDS that `ext` names, into its place in `refs`.
    fn textures(&self, ext: &Value, refs: &mut LobeTextureRefs) -> Result<(), GltfError> {
        for (slot, (field, ..)) in refs.iter_mut().zip(LOBE_TEXTURE_FIELDS) {
            if let Some(t) = self.texture(ext, field)? {
                *slot = Some(t);
            }
        }
        Ok(())
    }

    /// The textureInfo in field `name` of `ext`, if there is one: a texture index below the
    /// file's count, a texture coordinates' set, a finite scale and transform.
    fn texture(&self, ext: &Value, name: &'static str) -> Result<Option<TextureRef>, GltfError> {
        let Some(info) = ext.get(name) else { return Ok(None) };
        let bad = |why: String| GltfError::ExtensionTexture { material: self.material, field: name, why };
        let index = info.get("index").and_then(Value::as_u64).ok_or_else(|| bad("names no texture (no index)".into()))?;
        if index >= self.textures as u64 {
            return Err(bad(format!("names texture {index}, but there are {} textures", self.textures)));
        }
        let tex_coord = match info.get("texCoord") {
            None => 0,
            Some(v) => v.as_u64().and_then(|k| u32::try_from(k).ok()).ok_or_else(|| bad(format!("has texCoord {v}")))?,
        };
        let scale = match info.get("scale") {
            None => 1.0,
            Some(v) => v.as_f64().map(|x| x as f32).filter(|x| x.is_finite()).ok_or_else(|| bad(format!("has scale {v}")))?,
        };
        let transform = match info.pointer("/extensions/KHR_texture_transform") {
            None => Affine2::IDENTITY,
            Some(t) => texture_transform(t).ok_or(GltfError::TextureTransform { material: self.material })?,
        };
        Ok(Some(TextureRef { index: index as usize, tex_coord, transform, scale }))
    }
}

/// A KHR_texture_transform object as the affine map of texture coordinates it is
/// (`uv_affine`, as the loader's own texture_transform builds it); None where a part is not
/// finite numbers.
fn texture_transform(t: &Value) -> Option<Affine2> {
    let pair = |name: &str, default: Vec2| match t.get(name) {
        None => Some(default),
        Some(v) => {
            let a = v.as_array().filter(|a| a.len() == 2)?;
            Some(Vec2::new(a[0].as_f64()? as f32, a[1].as_f64()? as f32))
        }
    };
    let rotation = match t.get("rotation") {
        None => 0.0,
        Some(v) => v.as_f64()? as f32,
    };
    let affine = uv_affine(pair("offset", Vec2::ZERO)?, rotation, pair("scale", Vec2::ONE)?);
    affine.is_finite().then_some(affine)
}
