//! KHR_materials_variants: a file's named sets of materials (a shoe in three colours); `--variant
//! NAME` draws each primitive with the material its mappings give that variant, the others with
//! their own material.

use super::GltfError;
use serde_json::Value;

/// The variants' names, in the file's order (empty without the extension).
pub(super) fn variant_names(doc: &gltf::Document) -> Vec<String> {
    let names = doc.extension_value("KHR_materials_variants").and_then(|v| v.get("variants")).and_then(Value::as_array);
    names.into_iter().flatten().map(|v| v.get("name").and_then(Value::as_str).unwrap_or("").to_owned()).collect()
}

/// The index of the variant called `name`.
pub(super) fn variant_index(doc: &gltf::Document, name: &str) -> Result<usize, GltfError> {
    let names = variant_names(doc);
    names.iter().position(|n| n == name).ok_or_else(|| GltfError::UnknownVariant { name: name.to_owned(), known: names })
}

/// The material a primitive is drawn with under `variant`: its mapping's where one names the
/// variant, else its own.
pub(super) fn material_of<'d>(
    doc: &'d gltf::Document,
    primitive: &gltf::Primitive<'d>,
    variant: Option<usize>,
) -> Result<gltf::Material<'d>, GltfError> {
    let Some(variant) = variant else { return Ok(primitive.material()) };
    let mappings = primitive.extension_value("KHR_materials_variants").and_then(|v| v.get("mappings")).and_then(Value::as_array);
    for mapping in mappings.into_iter().flatten() {
        let names_it =
            mapping.get("variants").and_then(Value::as_array).is_some_and(|v| v.iter().any(|i| i.as_u64() == Some(variant as u64)));
        if names_it {
            let index = mapping.get("material").and_then(Value::as_u64).unwrap_or(u64::MAX);
            let materials = doc.materials().len();
            return usize::try_from(index).ok().and_then(|i| doc.materials().nth(i)).ok_or(GltfError::VariantMaterial { index, materials });
        }
    }
    Ok(primitive.material())
}
