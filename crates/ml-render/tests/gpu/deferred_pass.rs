//! The deferred render pass (docs/DESIGN.md#deferred-shading-in-one-render-pass): one
//! VkRenderPass with two subpasses, the second reading what the first wrote as input
//! attachments. Checked on the pass's description (what `vkCreateRenderPass` gets), on the
//! compiled lighting shaders (SPIR-V reflection: they really declare those input attachments),
//! and by rendering with validation on (the layer checks each pipeline against its subpass;
//! `techniques.rs` compares the images).

use crate::common;

use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::Scene;
use ml_render::internals::describe;
use ml_render::internals::{Output, HDR_FORMAT};
use ml_render::{gbuffer_bytes_per_pixel, gbuffer_images, GBufferKind};
use ml_render::{RenderSettings, Technique};
use ml_vk::vk;
use spirq::prelude::*;
use spirq::ty::DescriptorType;

#[test]
fn deferred_pass_has_two_subpasses_joined_by_input_attachments() {
    for kind in [GBufferKind::Base, GBufferKind::Material, GBufferKind::Lobes] {
        check_two_subpasses(kind);
    }
    // The G-buffer is compact: target ≤ 16 bytes per pixel besides depth (the seed's: 68),
    // 22 where objects have textures of their own, 38 where their PBR extensions vary per
    // point.
    assert_eq!(gbuffer_bytes_per_pixel(GBufferKind::Base), 16);
    assert_eq!(gbuffer_bytes_per_pixel(GBufferKind::Material), 22);
    assert_eq!(gbuffer_bytes_per_pixel(GBufferKind::Lobes), 38);
}

fn check_two_subpasses(kind: GBufferKind) {
    let images = gbuffer_images(kind);
    assert_eq!(images.len(), [3, 5, 6][kind as usize]);
    let d = describe(vk::Format::D32_SFLOAT, Output::Subpasses, images, (false, vk::SampleCountFlags::TYPE_1));
    assert_eq!(d.subpasses.len(), 2);
    let (gbuffer, lighting) = (&d.subpasses[0], &d.subpasses[1]);
    // Subpass 1 reads exactly what subpass 0 wrote: its colour attachments and its depth.
    let mut written: Vec<u32> = gbuffer.colour.iter().map(|r| r.attachment).collect();
    written.push(gbuffer.depth.expect("subpass 0 has depth").attachment);
    let mut read: Vec<u32> = lighting.inputs.iter().map(|r| r.attachment).collect();
    read.sort_unstable();
    written.sort_unstable();
    assert_eq!(read, written, "subpass 1's input attachments");
    assert!(lighting.depth.is_none());
    // ... into the HDR target, which alone is stored; the G-buffer never leaves the pass.
    assert_eq!(lighting.colour.len(), 1);
    let hdr = d.attachments[lighting.colour[0].attachment as usize];
    assert_eq!(hdr.format, HDR_FORMAT);
    assert_eq!(hdr.store_op, vk::AttachmentStoreOp::STORE);
    for a in &written {
        assert_eq!(d.attachments[*a as usize].store_op, vk::AttachmentStoreOp::DONT_CARE, "attachment {a} is stored");
    }
    // The dependency 0 → 1 (docs/DESIGN.md#deferred-shading-in-one-render-pass): attachment
    // writes → input-attachment reads, by region.
    let dep = d.dependencies.iter().find(|x| x.src_subpass == 0 && x.dst_subpass == 1).expect("a 0 → 1 dependency");
    assert!(dep.src_access_mask.contains(vk::AccessFlags::COLOR_ATTACHMENT_WRITE | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE));
    assert!(dep.src_stage_mask.contains(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS));
    assert_eq!(dep.dst_access_mask, vk::AccessFlags::INPUT_ATTACHMENT_READ);
    assert_eq!(dep.dst_stage_mask, vk::PipelineStageFlags::FRAGMENT_SHADER);
    assert_eq!(dep.dependency_flags, vk::DependencyFlags::BY_REGION);
    assert_eq!(d.attachments[0].format, vk::Format::R32G32_SFLOAT);
    assert_eq!(d.attachments[1].format, vk::Format::R32_UINT);
    assert!(d.attachments.iter().zip(images).all(|(a, g)| a.format == g.format));
    assert_eq!(d.attachments.len(), images.len() + 2, "the G-buffer, depth and HDR");
}

#[test]
fn lighting_shaders_load_the_gbuffer_as_input_attachments() {
    use ml_shaders::*;
    use GBufferKind::{Base, Lobes, Material};
    for (name, spirv, kind) in [
        ("deferred.frag", DEFERRED_FRAG, Base),
        ("deferred_clustered.frag", DEFERRED_CLUSTERED_FRAG, Base),
        ("deferred_textured.frag", DEFERRED_TEXTURED_FRAG, Material),
        ("deferred_clustered_textured.frag", DEFERRED_CLUSTERED_TEXTURED_FRAG, Material),
        ("deferred_lobes.frag", DEFERRED_LOBES_FRAG, Lobes),
        ("deferred_clustered_lobes.frag", DEFERRED_CLUSTERED_LOBES_FRAG, Lobes),
        ("deferred_samples.frag", DEFERRED_SAMPLES_FRAG, Base),
        ("deferred_clustered_samples.frag", DEFERRED_CLUSTERED_SAMPLES_FRAG, Base),
        ("deferred_textured_samples.frag", DEFERRED_TEXTURED_SAMPLES_FRAG, Material),
        ("deferred_clustered_textured_samples.frag", DEFERRED_CLUSTERED_TEXTURED_SAMPLES_FRAG, Material),
        ("deferred_lobes_samples.frag", DEFERRED_LOBES_SAMPLES_FRAG, Lobes),
        ("deferred_clustered_lobes_samples.frag", DEFERRED_CLUSTERED_LOBES_SAMPLES_FRAG, Lobes),
    ] {
        let d = describe(vk::Format::D32_SFLOAT, Output::Subpasses, gbuffer_images(kind), (false, vk::SampleCountFlags::TYPE_1));
        let inputs = d.subpasses[1].inputs.len() as u32;
        let words: Vec<u32> = spirv.spirv.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        let entries = ReflectConfig::new().spv(words).ref_all_rscs(true).reflect().expect("reflect");
        let mut indices: Vec<u32> = entries[0]
            .vars
            .iter()
            .filter_map(|v| match v {
                Variable::Descriptor { desc_ty: DescriptorType::InputAttachment(i), .. } => Some(*i),
                _ => None,
            })
            .collect();
        indices.sort_unstable();
        assert_eq!(indices, (0..inputs).collect::<Vec<_>>(), "{name}: input_attachment_index of its subpassInputs");
    }
}

/// Anti-aliasing: subpass 0 draws into multisampled attachments, which the lighting subpass
/// reads sample by sample into the single-sampled HDR target; the forward pass's multisampled
/// colour is resolved into the HDR target at its end.
#[test]
fn multisampled_passes_keep_samples_inside_and_one_value_a_pixel_out() {
    let four = vk::SampleCountFlags::TYPE_4;
    let d = describe(vk::Format::D32_SFLOAT, Output::Subpasses, gbuffer_images(GBufferKind::Lobes), (false, four));
    let hdr = d.subpasses[1].colour[0].attachment as usize;
    for (i, a) in d.attachments.iter().enumerate() {
        assert_eq!(a.samples, if i == hdr { vk::SampleCountFlags::TYPE_1 } else { four }, "attachment {i}");
    }
    let f = describe(vk::Format::D32_SFLOAT, Output::Color, &[], (false, four));
    let s = &f.subpasses[0];
    let (colour, resolve) = (&f.attachments[s.colour[0].attachment as usize], &f.attachments[s.resolve[0].attachment as usize]);
    assert_eq!((colour.samples, colour.store_op), (four, vk::AttachmentStoreOp::DONT_CARE));
    assert_eq!(
        (resolve.samples, resolve.store_op, resolve.format),
        (vk::SampleCountFlags::TYPE_1, vk::AttachmentStoreOp::STORE, HDR_FORMAT)
    );
    assert_eq!(f.attachments[s.depth.expect("depth").attachment as usize].samples, four);
}

#[test]
fn deferred_renders_with_validation_clean_and_times_its_passes() {
    let scene = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
    for technique in [Technique::Deferred, Technique::DeferredClustered] {
        let mut settings = RenderSettings::new(technique, 96, 64);
        settings.frames = 3;
        // common::render fails on any validation message.
        let out = common::render(scene.clone(), settings);
        let passes: Vec<&str> = out.stats.gpu_ms().expect("timestamps").iter().map(|(name, _)| *name).collect();
        assert_eq!(passes, ["g-buffer + lighting", "tone map"], "{}", technique.name());
        // Something was lit and the background kept its colour.
        assert!(out.rgba.chunks_exact(4).any(|p| p[0] > 100), "{}: nothing lit", technique.name());
        assert_eq!(common::pixel(&out, 0, 0), [5, 5, 5], "{}: background", technique.name());
    }
}
