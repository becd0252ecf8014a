//! The shading models by name: what a scene is lit with. The renderer compiles its pipelines
//! for one (ml-render); the CPU references of them are in shading.rs and blinn_phong.rs.

use crate::SceneError;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShadingModel {
    /// Specular-only Cook–Torrance, an ambient factor, gamma.
    Seed,
    /// Blinn-Phong with a shadowed sun, a spot light, textures and reflections.
    BlinnPhong,
    /// The seed's specular term plus Lambert diffuse weighted by (1 − F)(1 − metallic), HDR
    /// tone-mapped (ACES) before gamma.
    Pbr,
}

impl ShadingModel {
    pub const ALL: [ShadingModel; 3] = [ShadingModel::Seed, ShadingModel::BlinnPhong, ShadingModel::Pbr];

    pub fn name(self) -> &'static str {
        match self {
            ShadingModel::Seed => "seed",
            ShadingModel::BlinnPhong => "blinn-phong",
            ShadingModel::Pbr => "pbr",
        }
    }

    pub fn from_name(name: &str) -> Result<ShadingModel, SceneError> {
        crate::error::find_named("shading model", &ShadingModel::ALL, ShadingModel::name, name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_list_the_choices() {
        for m in ShadingModel::ALL {
            assert_eq!(ShadingModel::from_name(m.name()).unwrap(), m);
        }
        let e = ShadingModel::from_name("phong").unwrap_err().to_string();
        assert_eq!(e, "unknown shading model 'phong': expected one of seed, blinn-phong, pbr");
    }
}
