//! A glTF material's textures besides the base colour → [`SurfaceMaps`]: normal (with
//! `scale`), occlusion (with `strength`), emissive (`emissiveFactor` ×
//! `KHR_materials_emissive_strength`, × texture), metallic-roughness; and every texture's
//! `KHR_texture_transform`, read from the file's JSON (the `gltf` crate exposes it on only
//! some texture infos).
//!
//! `TEXCOORD_0` and `TEXCOORD_1` are read: a texture on another set (after the transform's
//! `texCoord` override) is a warning and not bound.

use std::path::Path;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use serde_json::Value;

use super::buffers::Buffers;
use super::texture::Textures;
use crate::scene::mesh::MAX_TEXCOORD;
use crate::scene::surface_maps::{
    turns_no_normal, MapTexture, SurfaceMaps, TextureTransform, MAX_EMISSIVE, MAX_NORMAL_SCALE,
    UV_SETS,
};
use crate::scene::{short3, shown, Short, Texture};

/// The file's materials' `KHR_texture_transform` objects, as plain JSON. Only the texture
/// infos' extensions are built: the rest of the document (`extras` too) is skipped, at any
/// depth.
pub(super) struct RawMaterials(Vec<RawMaterial>);

#[derive(Default, serde::Deserialize)]
#[serde(default, rename_all = "camelCase")]
struct RawMaterial {
    pbr_metallic_roughness: Option<RawPbr>,
    normal_texture: Option<RawInfo>,
    occlusion_texture: Option<RawInfo>,
    emissive_texture: Option<RawInfo>,
}

#[derive(Default, serde::Deserialize)]
#[serde(default, rename_all = "camelCase")]
struct RawPbr {
    base_color_texture: Option<RawInfo>,
    metallic_roughness_texture: Option<RawInfo>,
}

#[derive(Default, serde::Deserialize)]
#[serde(default)]
struct RawInfo {
    extensions: Option<RawInfoExtensions>,
}

#[derive(Default, serde::Deserialize)]
#[serde(default)]
struct RawInfoExtensions {
    #[serde(rename = "KHR_texture_transform")]
    texture_transform: Option<Value>,
}

impl RawMaterials {
    /// From the file's JSON chunk (already parsed once by the `gltf` crate, so valid). Where
    /// a transform cannot be read (nested past serde_json's 128 levels), all are ignored,
    /// with a warning.
    pub fn parse(json: &[u8], warnings: &mut Vec<String>) -> RawMaterials {
        #[derive(serde::Deserialize)]
        struct Root {
            #[serde(default)]
            materials: Option<Vec<RawMaterial>>,
        }
        match serde_json::from_slice::<Root>(json) {
            Ok(root) => RawMaterials(root.materials.unwrap_or_default()),
            Err(e) => {
                warnings.push(format!(
                    "materials: KHR_texture_transform unreadable ({}, line {} column {}); \
                     every texture is drawn untransformed",
                    match e.classify() {
                        serde_json::error::Category::Data => "not of the schema's types",
                        _ => "nested too deep",
                    },
                    e.line(),
                    e.column()
                ));
                RawMaterials(Vec::new())
            }
        }
    }

    /// The `KHR_texture_transform` of the texture info at `path` (keys from the material
    /// object) of material `index`.
    fn transform(&self, index: Option<usize>, path: &[&str]) -> Option<&Value> {
        let m = self.0.get(index?)?;
        let pbr = m.pbr_metallic_roughness.as_ref();
        let info = match path {
            ["normalTexture"] => m.normal_texture.as_ref(),
            ["occlusionTexture"] => m.occlusion_texture.as_ref(),
            ["emissiveTexture"] => m.emissive_texture.as_ref(),
            ["pbrMetallicRoughness", "baseColorTexture"] => pbr?.base_color_texture.as_ref(),
            ["pbrMetallicRoughness", "metallicRoughnessTexture"] => {
                pbr?.metallic_roughness_texture.as_ref()
            }
            _ => {
                debug_assert!(false, "no texture info at {path:?}");
                None
            }
        };
        info?.extensions.as_ref()?.texture_transform.as_ref()
    }
}

/// One texture slot of a material: where it is in the JSON, its glTF name for messages.
pub(super) struct Slot<'a> {
    pub name: &'a str,
    pub path: &'a [&'a str],
    pub texture: gltf::Texture<'a>,
    pub tex_coord: u32,
}

/// What the maps converter needs from the file.
pub(super) struct Sources<'a, 'b> {
    pub raw: &'b RawMaterials,
    pub textures: &'b mut Textures,
    pub buffers: &'b mut Buffers<'a>,
    pub gltf_path: &'b Path,
}

/// `KHR_texture_transform` of the texture info at `path` and the set it reads; a malformed
/// one is ignored with a warning.
pub(super) fn transform_of(
    raw: &RawMaterials,
    index: Option<usize>,
    path: &[&str],
    tex_coord: u32,
    field: &str,
    warnings: &mut Vec<String>,
) -> (TextureTransform, u32) {
    // The transform reads the set, where a mesh can have it.
    let with_set = |(t, set): (TextureTransform, u32)| {
        let uv_set = if set < UV_SETS { set } else { 0 };
        (TextureTransform { uv_set, ..t }, set)
    };
    let Some(ext) = raw.transform(index, path) else {
        return with_set((TextureTransform::IDENTITY, tex_coord));
    };
    let pair = |key: &str, default: Vec2| -> Option<Vec2> {
        match ext.get(key) {
            None => Some(default),
            Some(Value::Array(a)) if a.len() == 2 => {
                Some(Vec2::new(a[0].as_f64()? as f32, a[1].as_f64()? as f32))
            }
            Some(_) => None,
        }
    };
    let rotation = match ext.get("rotation") {
        None => Some(0.0),
        Some(v) => v.as_f64().map(|r| r as f32),
    };
    // A set number that is not one (a string, a fraction, past 2³² − 1) makes the whole
    // extension malformed, as an offset that is not a number does.
    let set = match ext.get("texCoord") {
        None => Some(tex_coord),
        Some(v) => v.as_u64().and_then(|t| u32::try_from(t).ok()),
    };
    let parsed = match (
        pair("offset", Vec2::ZERO),
        rotation,
        pair("scale", Vec2::ONE),
        set,
    ) {
        (Some(offset), Some(rotation), Some(scale), Some(set)) => Some((
            TextureTransform {
                offset,
                rotation,
                scale,
                uv_set: 0,
            },
            set,
        )),
        _ => None,
    };
    let usable =
        |(t, _): &(TextureTransform, u32)| t.is_usable() && t.rows().iter().all(|r| r.is_finite());
    match parsed.filter(usable).map(with_set) {
        Some(parsed) => parsed,
        None => {
            warnings.push(format!(
                "{field}.extensions.KHR_texture_transform: malformed (offset and scale are \
                 two numbers within ±{MAX_TEXCOORD:e}, rotation one, all finite, texCoord a \
                 set number); ignored"
            ));
            with_set((TextureTransform::IDENTITY, tex_coord))
        }
    }
}

/// The message for a texture on a set past [`UV_SETS`]: not bound.
pub(super) fn unread_set(field: &str, set: u32, what: &str) -> String {
    format!("{field}: uses TEXCOORD_{set}; only TEXCOORD_0 and TEXCOORD_1 are read, so {what}")
}

/// Loads one slot's texture with its transform (`None`: absent, on another texture
/// coordinate set, or not decodable — each warned).
pub(super) fn load_slot(
    slot: Slot<'_>,
    index: Option<usize>,
    field: &str,
    src: &mut Sources<'_, '_>,
    warnings: &mut Vec<String>,
) -> Result<Option<MapTexture>, String> {
    let tfield = format!("{field}.{}", slot.path.join("."));
    let (transform, tex_coord) =
        transform_of(src.raw, index, slot.path, slot.tex_coord, &tfield, warnings);
    if tex_coord >= UV_SETS {
        let what = format!("the {} texture is not bound", slot.name);
        warnings.push(unread_set(&tfield, tex_coord, &what));
        return Ok(None);
    }
    let texture = src
        .textures
        .load_texture(&slot.texture, src.buffers, src.gltf_path, warnings)
        .map_err(|e| format!("{tfield}: {e}"))?;
    Ok(texture.map(|texture| MapTexture { texture, transform }))
}

/// Makes every slot of one material that reads an image read it through one sampling, the
/// first slot's (base colour, normal, emissive, occlusion, metallic-roughness): a draw binds
/// each image once (on ES 2.0 colour and data share an upload), and its sampling is the
/// texture's. Each slot changed is warned of.
pub(super) fn one_sampling_per_image(
    base: &mut Option<Arc<Texture>>,
    maps: &mut SurfaceMaps,
    field: &str,
    warnings: &mut Vec<String>,
) {
    let mut slots: Vec<(&str, &mut Arc<Texture>)> = Vec::new();
    if let Some(t) = base.as_mut() {
        slots.push(("base colour", t));
    }
    let maps = [
        ("normal", &mut maps.normal),
        ("emissive", &mut maps.emissive_texture),
        ("occlusion", &mut maps.occlusion),
        ("metallic-roughness", &mut maps.metallic_roughness),
    ];
    for (name, map) in maps {
        if let Some(map) = map.as_mut() {
            slots.push((name, &mut map.texture));
        }
    }
    for i in 1..slots.len() {
        let (earlier, later) = slots.split_at_mut(i);
        let (name, texture) = &mut later[0];
        let first = earlier
            .iter()
            .find(|(_, e)| Arc::ptr_eq(&e.image, &texture.image) && e.sampling != texture.sampling);
        if let Some((first_name, first)) = first {
            warnings.push(format!(
                "{field}: the {name} and {first_name} textures read one image ({}) through \
                 different samplers; a draw reads an image through one, so the {name} texture \
                 takes the {first_name} one's",
                shown::name(&texture.name)
            ));
            **texture = Arc::new(texture.with_sampling(first.sampling));
        }
    }
}

/// The maps of material `m` (the base colour's transform is the caller's).
pub(super) fn convert(
    m: &gltf::Material,
    field: &str,
    src: &mut Sources<'_, '_>,
    warnings: &mut Vec<String>,
) -> Result<SurfaceMaps, String> {
    let index = m.index();
    let mut maps = SurfaceMaps::default();
    if let Some(n) = m.normal_texture() {
        let slot = Slot {
            name: "normal",
            path: &["normalTexture"],
            texture: n.texture(),
            tex_coord: n.tex_coord(),
        };
        maps.normal = load_slot(slot, index, field, src, warnings)?;
        let path = format!("{field}.normalTexture.scale");
        maps.normal_scale = kept_in(
            n.scale(),
            (-MAX_NORMAL_SCALE, MAX_NORMAL_SCALE),
            1.0,
            &path,
            warnings,
        );
        // At scale 0 a map whose texels all point out of the surface changes no pixel: not
        // drawn, so it costs no upload, texture unit, tangents or coordinate set.
        if maps.normal_scale == 0.0
            && (maps.normal.as_ref()).is_some_and(|m| turns_no_normal(&m.texture.image))
        {
            maps.normal = None;
        }
    }
    if let Some(o) = m.occlusion_texture() {
        let slot = Slot {
            name: "occlusion",
            path: &["occlusionTexture"],
            texture: o.texture(),
            tex_coord: o.tex_coord(),
        };
        maps.occlusion = load_slot(slot, index, field, src, warnings)?;
        let path = format!("{field}.occlusionTexture.strength");
        maps.occlusion_strength = kept_in(o.strength(), (0.0, 1.0), 1.0, &path, warnings);
    }
    if let Some(info) = m.pbr_metallic_roughness().metallic_roughness_texture() {
        let slot = Slot {
            name: "metallic-roughness",
            path: &["pbrMetallicRoughness", "metallicRoughnessTexture"],
            texture: info.texture(),
            tex_coord: info.tex_coord(),
        };
        maps.metallic_roughness = load_slot(slot, index, field, src, warnings)?;
    }
    let (e, emissive) = emission(m);
    if emissive != e {
        warnings.push(format!(
            "{field}: emissiveFactor × KHR_materials_emissive_strength {} clamped to {} \
             (the fp16 colour tier's range, the hue kept)",
            short3(e),
            short3(emissive)
        ));
    }
    maps.emissive = emissive;
    if let Some(info) = m.emissive_texture() {
        let slot = Slot {
            name: "emissive",
            path: &["emissiveTexture"],
            texture: info.texture(),
            tex_coord: info.tex_coord(),
        };
        if emissive.max_element() > 0.0 {
            maps.emissive_texture = load_slot(slot, index, field, src, warnings)?;
        }
    }
    Ok(maps)
}

/// `m`'s emission, `emissiveFactor` × `KHR_materials_emissive_strength`, as the file gives it
/// and as kept: within [0, `MAX_EMISSIVE`], scaled down as a whole where a channel passes it,
/// so its hue is kept (clamped channel by channel, (1e6, 5e5, 0) became white-yellow
/// (1024, 1024, 0)). A strength past f32 (1e300 in the file) is infinite: the factor's hue at
/// the cap (the limit of ever larger strengths).
fn emission(m: &gltf::Material) -> (Vec3, Vec3) {
    let strength = m.emissive_strength().unwrap_or(1.0);
    let factor = Vec3::from(m.emissive_factor());
    // Negative and NaN channels are 0 (`>` is false for NaN).
    let factor = Vec3::select(factor.cmpgt(Vec3::ZERO), factor, Vec3::ZERO);
    let written = Vec3::from(m.emissive_factor()) * strength;
    // In f64, where the product of two f32s is finite; NaN strength is 0, infinity stays.
    let strength = if strength > 0.0 {
        f64::from(strength)
    } else {
        0.0
    };
    let brightest = f64::from(factor.max_element());
    let kept = if brightest == 0.0 || strength == 0.0 {
        Vec3::ZERO
    } else if brightest.is_infinite() {
        // A factor past f32 in the file: its infinite channels at the cap, the rest dark.
        Vec3::select(
            factor.cmpeq(Vec3::INFINITY),
            Vec3::splat(MAX_EMISSIVE),
            Vec3::ZERO,
        )
    } else if brightest * strength <= f64::from(MAX_EMISSIVE) {
        (factor.as_dvec3() * strength).as_vec3()
    } else {
        let cap = f64::from(MAX_EMISSIVE) / brightest;
        (factor.as_dvec3() * cap)
            .as_vec3()
            .min(Vec3::splat(MAX_EMISSIVE))
    };
    (written, kept)
}

/// `value` within `range`, or `default` where it is not finite (past f32 in the file), with a
/// warning naming `path` whenever what is kept is not what was written.
fn kept_in(
    value: f32,
    range: (f32, f32),
    default: f32,
    path: &str,
    warnings: &mut Vec<String>,
) -> f32 {
    let kept = if value.is_finite() {
        value.clamp(range.0, range.1)
    } else {
        default
    };
    if kept != value {
        warnings.push(format!(
            "{path}: {} taken as {kept} (its range is [{}, {}])",
            Short(value),
            range.0,
            range.1
        ));
    }
    kept
}
