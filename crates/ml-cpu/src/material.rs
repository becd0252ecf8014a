//! The seed's materials: albedo with roughness 0.1 and metallic 1.0.

use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub albedo: Vec3,
    pub roughness: f32,
    pub metallic: f32,
}

/// Name and albedo of every built-in material, in the seed's order.
pub const NAMED_ALBEDOS: [(&str, [f32; 3]); 11] = [
    ("gold", [1.0, 0.765557, 0.336057]),
    ("copper", [0.955008, 0.637427, 0.538163]),
    ("chromium", [0.549585, 0.556114, 0.554256]),
    ("nickel", [0.659777, 0.608679, 0.525649]),
    ("titanium", [0.541931, 0.496791, 0.449419]),
    ("cobalt", [0.662124, 0.654864, 0.633732]),
    ("platinum", [0.672411, 0.637331, 0.585456]),
    ("white", [1.0, 1.0, 1.0]),
    ("red", [1.0, 0.0, 0.0]),
    ("blue", [0.0, 0.0, 1.0]),
    ("black", [0.0, 0.0, 0.0]),
];

/// Roughness and metallic of every seed material.
pub const SEED_ROUGHNESS: f32 = 0.1;
pub const SEED_METALLIC: f32 = 1.0;

impl Material {
    /// A built-in material by (lower-case) name.
    pub fn named(name: &str) -> Result<Material, crate::SceneError> {
        NAMED_ALBEDOS.iter().find(|(n, _)| *n == name).map(|(_, a)| Material::seed(*a)).ok_or_else(|| crate::SceneError::UnknownName {
            kind: "material",
            name: name.to_owned(),
            expected: NAMED_ALBEDOS.map(|(n, _)| n).join(", "),
        })
    }

    /// Every built-in material, in the seed's order.
    pub fn built_in() -> [Material; NAMED_ALBEDOS.len()] {
        NAMED_ALBEDOS.map(|(_, a)| Material::seed(a))
    }

    /// The name of the built-in material this is, if it is one.
    pub fn name(&self) -> Option<&'static str> {
        NAMED_ALBEDOS.iter().find(|(_, a)| Material::seed(*a) == *self).map(|(n, _)| *n)
    }

    fn seed(albedo: [f32; 3]) -> Material {
        Material { albedo: Vec3::from(albedo), roughness: SEED_ROUGHNESS, metallic: SEED_METALLIC }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_resolves_and_unknown_names_list_the_choices() {
        for (name, albedo) in NAMED_ALBEDOS {
            let m = Material::named(name).unwrap();
            assert_eq!(m.albedo, Vec3::from(albedo));
            assert_eq!((m.roughness, m.metallic), (0.1, 1.0));
        }
        for m in Material::built_in() {
            assert_eq!(Material::named(m.name().unwrap()), Ok(m));
        }
        assert_eq!(Material { roughness: 0.5, ..Material::built_in()[0] }.name(), None);
        let err = Material::named("unobtainium").unwrap_err().to_string();
        assert!(err.contains("unobtainium") && err.contains("gold") && err.contains("black"), "{err}");
    }
}
