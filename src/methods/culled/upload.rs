//! Stage pack and upload: the visible lights, the grid's lists and the index list packed into
//! texels (in buffers kept between frames) and uploaded to the next texture set of the ring.

use std::time::Instant;

use crate::cluster::assign::Assignment;
use crate::cluster::grid::ClusterGrid;
use crate::cluster::headroom::room_for;
use crate::cluster::pack::{pack_grid_into, pack_indices_into, GridEncoding, PackedTexels};
use crate::cluster::pack::{pack_lights_into, LightEncoding, PackedLights};
use crate::cluster::view_light::GpuLight;
use crate::gl::texture::{DataFormat, DataTexture, SHRINK_AFTER};
use crate::gl::{Device, EsVersion};
use crate::methods::FrameContext;
use crate::Error;

/// Texture sets in the upload ring.
pub const RING: usize = 3;

/// One frame's textures: light records, the grid (cascade tables and cell list starts) and
/// the index list.
pub(super) struct TextureSet {
    pub lights: DataTexture,
    light_encoding: LightEncoding,
    pub grid: DataTexture,
    pub indices: DataTexture,
}

impl TextureSet {
    fn new(dev: &Device, light_encoding: LightEncoding) -> Result<TextureSet, Error> {
        let light_format = match light_encoding {
            LightEncoding::Float32 => DataFormat::Rgba32F,
            LightEncoding::Rgba8 => DataFormat::Rgba8,
        };
        let (grid, indices) = match dev.es() {
            EsVersion::Es2 => (DataFormat::Rgba8, DataFormat::Rgba8),
            EsVersion::Es3 => (DataFormat::R32Ui, DataFormat::Rgba16Ui),
        };
        Ok(TextureSet {
            lights: DataTexture::new(dev, light_format)?,
            light_encoding,
            grid: DataTexture::new(dev, grid)?,
            indices: DataTexture::new(dev, indices)?,
        })
    }

    fn destroy(mut self, dev: &Device) {
        self.lights.destroy(dev);
        self.grid.destroy(dev);
        self.indices.destroy(dev);
    }

    fn gpu_bytes(&self) -> usize {
        self.lights.gpu_bytes() + self.grid.gpu_bytes() + self.indices.gpu_bytes()
    }
}

/// The texture ring and what a frame packs, kept so a frame allocates nothing once they have
/// grown.
pub(super) struct Uploads {
    ring: Vec<Option<TextureSet>>,
    frame: usize,
    /// The ring slot and light ranges of the last upload, which a frame with the same lists
    /// draws with again ([`Uploads::last_upload`]).
    last: Option<(usize, [f32; 2])>,
    /// Frames drawn with the last upload's textures, its own included
    /// ([`Uploads::still_frame`]).
    frames_on_last: u32,
    /// The visible lights, their texels, the grid's and the index list's texels.
    visible: Vec<GpuLight>,
    lights: PackedLights,
    grid: PackedTexels,
    indices: PackedTexels,
}

impl Default for Uploads {
    fn default() -> Self {
        Uploads {
            ring: (0..RING).map(|_| None).collect(),
            frame: 0,
            last: None,
            frames_on_last: 0,
            visible: Vec::new(),
            lights: PackedLights::default(),
            grid: PackedTexels::default(),
            indices: PackedTexels::default(),
        }
    }
}

/// What a frame uploaded.
pub(super) struct Uploaded<'a> {
    /// The texture set the frame reads.
    pub set: &'a TextureSet,
    /// The RGBA8 light encoding's position and radius ranges.
    pub light_ranges: [f32; 2],
    /// Bytes uploaded.
    pub bytes: usize,
    /// Packing and upload time.
    pub ms: f64,
}

impl Uploads {
    /// Gives back what a burst of lights grew the packing buffers to. Not `in_use` (the last
    /// frame drew without the method), they are emptied and the last upload is not drawn
    /// again: the next frame packs and uploads anew.
    pub(super) fn fit_buffers(&mut self, in_use: bool) {
        use crate::cluster::headroom::fit_keeping;
        fit_keeping(&mut self.visible, in_use);
        fit_keeping(&mut self.lights.bytes, in_use);
        fit_keeping(&mut self.grid.bytes, in_use);
        fit_keeping(&mut self.indices.bytes, in_use);
        if !in_use {
            self.last = None;
        }
    }

    /// Packs the frame's visible lights, cell lists and index list, and uploads them into the
    /// ring's next set (made anew when the light encoding changed). Texels the allocator
    /// refuses are `method`'s error naming their size.
    pub(super) fn pack_and_upload(
        &mut self,
        ctx: &FrameContext,
        method: &str,
        grid: &ClusterGrid,
        assignment: &Assignment,
    ) -> Result<Uploaded<'_>, Error> {
        let dev = ctx.dev;
        let started = Instant::now();
        self.last = None;
        self.frames_on_last = 1;
        self.visible.clear();
        room_for(&mut self.visible, assignment.visible.len());
        let encoding = ctx.features.light_encoding();
        let visible = assignment.visible.iter().map(|&i| &ctx.lights[i as usize]);
        if encoding == LightEncoding::Rgba8 {
            // The lights that set the records' shared range are forward's.
            let volume = ctx.view_volume();
            let darkened = |l| crate::methods::unseen_lights::darkened_if_unseen(&volume, l);
            self.visible.extend(visible.map(darkened));
        } else {
            self.visible.extend(visible.copied());
        }
        let grid_encoding = GridEncoding::for_es(dev.es());
        pack_lights_into(&self.visible, ctx.features.light_layout(), &mut self.lights);
        // Refused, the frame is not drawn: the error names the size, as the assignment's does.
        pack_grid_into(grid, assignment, grid_encoding, &mut self.grid)
            .and_then(|()| pack_indices_into(&assignment.indices, grid_encoding, &mut self.indices))
            .map_err(|bytes| super::limits::lists_unallocated(method, bytes))?;

        let slot = next_slot(&mut self.frame);
        let set = set_at(&mut self.ring, slot, dev, encoding)?;
        let (lights, grid, indices) = (&self.lights, &self.grid, &self.indices);
        let uploaded = set
            .lights
            .upload(dev, lights.width, lights.height, &lights.bytes)
            .and_then(|()| set.grid.upload(dev, grid.width, grid.height, &grid.bytes))
            .and_then(|()| {
                (set.indices).upload(dev, indices.width, indices.height, &indices.bytes)
            });
        if let Err(e) = uploaded {
            // A failed frame keeps nothing it made: the next one to reach this slot makes it
            // anew (a game that renders on through failures held a set in every slot).
            if let Some(set) = self.ring[slot].take() {
                set.destroy(dev);
            }
            return Err(e.into());
        }
        let set = self.ring[slot].as_ref().expect("uploaded above");
        let light_ranges = [lights.pos_range, lights.radius_range];
        self.last = Some((slot, light_ranges));
        Ok(Uploaded {
            set,
            light_ranges,
            bytes: lights.bytes.len() + grid.bytes.len() + indices.bytes.len(),
            ms: started.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// The last upload's textures, for a frame whose lists and light records are that
    /// upload's (nothing uploaded, nothing rewritten); `None` when it failed or was freed.
    pub(super) fn last_upload(&self) -> Option<Uploaded<'_>> {
        let (slot, light_ranges) = self.last?;
        Some(Uploaded {
            set: self.ring[slot].as_ref()?,
            light_ranges,
            bytes: 0,
            ms: 0.0,
        })
    }

    /// The last upload's textures for a still frame, as [`Uploads::last_upload`], counting the
    /// frame: a texture its records have filled a quarter of at most for [`SHRINK_AFTER`]
    /// frames gets them again at their size, and at [`SHRINK_AFTER`] frames on one upload the
    /// ring's other sets, which a still frame does not read, are freed. A still scene after a
    /// burst of lights uploads nothing, and kept the burst's textures for good. Where that
    /// upload fails, the whole ring is freed.
    pub(super) fn still_frame(&mut self, dev: &Device) -> Result<Option<Uploaded<'_>>, Error> {
        let started = Instant::now();
        let Some((slot, light_ranges)) = self.last else {
            return Ok(None);
        };
        let Some(set) = self.ring[slot].as_mut() else {
            return Ok(None);
        };
        // Cleared while uploading: a failed upload leaves nothing to draw again.
        self.last = None;
        let (lights, grid, indices) = (&self.lights, &self.grid, &self.indices);
        let mut bytes = 0;
        let mut failed = None;
        for (texture, (width, height, records)) in [
            (
                &mut set.lights,
                (lights.width, lights.height, &lights.bytes),
            ),
            (&mut set.grid, (grid.width, grid.height, &grid.bytes)),
            (
                &mut set.indices,
                (indices.width, indices.height, &indices.bytes),
            ),
        ] {
            if texture.note_still_frame() {
                if let Err(e) = texture.upload(dev, width, height, records) {
                    failed = Some(e);
                    break;
                }
                bytes += records.len();
            }
        }
        if let Some(e) = failed {
            // Most likely out of memory: the ring's sets (the burst's size) go, and the next
            // frame uploads its lists into a set made at their size.
            self.destroy(dev);
            return Err(e.into());
        }
        self.last = Some((slot, light_ranges));
        self.frames_on_last = self.frames_on_last.saturating_add(1);
        if self.frames_on_last == SHRINK_AFTER {
            for (other, set) in self.ring.iter_mut().enumerate() {
                if let Some(set) = set.take_if(|_| other != slot) {
                    set.destroy(dev);
                }
            }
        }
        Ok(Some(Uploaded {
            set: self.ring[slot].as_ref().expect("drawn above"),
            light_ranges,
            bytes,
            ms: started.elapsed().as_secs_f64() * 1e3,
        }))
    }

    /// GPU bytes of all ring sets.
    pub(super) fn gpu_bytes(&self) -> usize {
        self.ring.iter().flatten().map(TextureSet::gpu_bytes).sum()
    }

    /// Frees the ring.
    pub(super) fn destroy(&mut self, dev: &Device) {
        self.last = None;
        for set in self.ring.iter_mut().filter_map(Option::take) {
            set.destroy(dev);
        }
    }
}

/// The ring's slot for this frame: the one used `RING` uploads ago.
fn next_slot(frame: &mut usize) -> usize {
    let slot = *frame % RING;
    *frame += 1;
    slot
}

/// The ring's set at `slot`, made anew when the light encoding changed.
fn set_at<'r>(
    ring: &'r mut [Option<TextureSet>],
    slot: usize,
    dev: &Device,
    encoding: LightEncoding,
) -> Result<&'r mut TextureSet, Error> {
    let slot = &mut ring[slot];
    if slot.as_ref().is_some_and(|s| s.light_encoding != encoding) {
        if let Some(old) = slot.take() {
            old.destroy(dev);
        }
    }
    if slot.is_none() {
        *slot = Some(TextureSet::new(dev, encoding)?);
    }
    Ok(slot.as_mut().expect("created above"))
}
