//! glTF's PBR material extensions read into `MaterialLobes`: KHR_materials_ior,
//! KHR_materials_specular, KHR_materials_clearcoat, KHR_materials_sheen,
//! KHR_materials_unlit, KHR_materials_transmission and KHR_materials_volume — their factors,
//! each checked against its extension's range. Their textures are not read: the factors apply
//! alone, and the loader says so once per material. The volume's thickness is in the mesh's
//! units; the loader scales it to the world's per object (`MaterialLobes::thickness`).

use super::{GltfError, MaterialName};
use crate::material_lobes::MaterialLobes;
use glam::Vec3;
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

/// The lobes of material `m`, and its extension textures left out ("clearcoat", …).
pub(super) fn material_lobes(m: &gltf::Material) -> Result<(MaterialLobes, Vec<&'static str>), GltfError> {
    let material = MaterialName(m.index());
    let mut lobes = MaterialLobes::default();
    let mut unread = Vec::new();
    let mut read = Reader { material, unread: &mut unread };
    if let Some(ext) = m.extension_value("KHR_materials_ior") {
        lobes.ior = read.number(ext, "ior", lobes.ior, 0.0..=MAX_IOR)?;
        if lobes.ior > 0.0 && lobes.ior < 1.0 {
            return Err(GltfError::Ior { material, value: lobes.ior });
        }
    }
    if let Some(ext) = m.extension_value("KHR_materials_specular") {
        lobes.specular = read.number(ext, "specularFactor", 1.0, 0.0..=1.0)?;
        lobes.specular_color = read.color(ext, "specularColorFactor", Vec3::ONE, 0.0..=f32::MAX)?;
        read.textures(ext, &[("specularTexture", "specular"), ("specularColorTexture", "specular colour")]);
    }
    if let Some(ext) = m.extension_value("KHR_materials_clearcoat") {
        lobes.clearcoat = read.number(ext, "clearcoatFactor", 0.0, 0.0..=1.0)?;
        lobes.clearcoat_roughness = read.number(ext, "clearcoatRoughnessFactor", 0.0, 0.0..=1.0)?;
        read.textures(
            ext,
            &[
                ("clearcoatTexture", "clearcoat"),
                ("clearcoatRoughnessTexture", "clearcoat roughness"),
                ("clearcoatNormalTexture", "clearcoat normal"),
            ],
        );
    }
    if let Some(ext) = m.extension_value("KHR_materials_sheen") {
        lobes.sheen_color = read.color(ext, "sheenColorFactor", Vec3::ZERO, 0.0..=1.0)?;
        lobes.sheen_roughness = read.number(ext, "sheenRoughnessFactor", 0.0, 0.0..=1.0)?;
        read.textures(ext, &[("sheenColorTexture", "sheen colour"), ("sheenRoughnessTexture", "sheen roughness")]);
    }
    if let Some(ext) = m.extension_value("KHR_materials_transmission") {
        lobes.transmission = read.number(ext, "transmissionFactor", 0.0, 0.0..=1.0)?;
        read.textures(ext, &[("transmissionTexture", "transmission")]);
    }
    if let Some(ext) = m.extension_value("KHR_materials_volume") {
        lobes.thickness = read.number(ext, "thicknessFactor", 0.0, 0.0..=f32::MAX)?;
        lobes.attenuation_distance = read.number(ext, "attenuationDistance", f32::INFINITY, f32::MIN_POSITIVE..=f32::INFINITY)?;
        lobes.attenuation_color = read.color(ext, "attenuationColor", Vec3::ONE, 0.0..=1.0)?;
        read.textures(ext, &[("thicknessTexture", "thickness")]);
    }
    lobes.unlit = m.extension_value("KHR_materials_unlit").is_some();
    Ok((lobes, unread))
}

struct Reader<'a> {
    material: MaterialName,
    unread: &'a mut Vec<&'static str>,
}

impl Reader<'_> {
    /// Field `name` of extension object `ext`: `default` where absent, else a number in `range`.
    fn number(&mut self, ext: &Value, name: &'static str, default: f32, range: std::ops::RangeInclusive<f32>) -> Result<f32, GltfError> {
        let Some(v) = ext.get(name) else { return Ok(default) };
        let value = v.as_f64().map_or(f32::NAN, |x| x as f32);
        if !range.contains(&value) {
            return Err(GltfError::ExtensionFactor { material: self.material, field: name, value: v.to_string(), range });
        }
        Ok(value)
    }

    /// An RGB field: three numbers, each in `range`.
    fn color(&mut self, ext: &Value, name: &'static str, default: Vec3, range: std::ops::RangeInclusive<f32>) -> Result<Vec3, GltfError> {
        let Some(v) = ext.get(name) else { return Ok(default) };
        let parts: Option<Vec<f32>> =
            v.as_array().filter(|a| a.len() == 3).map(|a| a.iter().map(|x| x.as_f64().map_or(f32::NAN, |x| x as f32)).collect());
        match parts {
            Some(p) if p.iter().all(|x| range.contains(x)) => Ok(Vec3::new(p[0], p[1], p[2])),
            _ => Err(GltfError::ExtensionFactor { material: self.material, field: name, value: v.to_string(), range }),
        }
    }

    /// Notes each texture field present: its factor applies without it.
    fn textures(&mut self, ext: &Value, fields: &[(&str, &'static str)]) {
        self.unread.extend(fields.iter().filter(|(field, _)| ext.get(field).is_some()).map(|(_, what)| *what));
    }
}
