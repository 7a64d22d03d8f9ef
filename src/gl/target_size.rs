//! The sizes a context can allocate a render target at: every target the renderer makes checks
//! its size here first, so a frame larger than the driver's textures or renderbuffers is an
//! error naming the limit rather than a GL error from the allocation (a viewport may be larger
//! than either: `GL_MAX_VIEWPORT_DIMS` is a separate limit).

use super::{Caps, GlError};

/// What a render target is made of.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TargetStorage {
    /// Some attachment is a texture (`GL_MAX_TEXTURE_SIZE`).
    pub textures: bool,
    /// Some attachment is a renderbuffer (`GL_MAX_RENDERBUFFER_SIZE`).
    pub renderbuffers: bool,
}

/// `Ok` when `caps` can allocate a `width × height` target of `storage`; else an error naming
/// `what` (the target, as "a deferred G-buffer") and the limit it passes.
pub(crate) fn check(
    caps: &Caps,
    what: &'static str,
    (width, height): (u32, u32),
    storage: TargetStorage,
) -> Result<(), GlError> {
    if width == 0 || height == 0 {
        return Err(GlError::Unsupported(format!(
            "{what} of {width}×{height} pixels: both sides must be at least 1"
        )));
    }
    let limits = [
        (
            storage.textures,
            caps.max_texture_size,
            "GL_MAX_TEXTURE_SIZE",
        ),
        (
            storage.renderbuffers,
            caps.max_renderbuffer_size,
            "GL_MAX_RENDERBUFFER_SIZE",
        ),
    ];
    for (applies, max, limit) in limits {
        // A driver that reports no limit (0) is taken at its word by the allocation itself.
        if applies && max > 0 && width.max(height) > max as u32 {
            return Err(GlError::TooLarge {
                what,
                width,
                height,
                limit,
                max_width: max as u32,
                max_height: max as u32,
            });
        }
    }
    Ok(())
}

/// The size a frame-sized texture of `caps` is allocated at: the frame's, or on a context that
/// refuses render targets of other sizes ([`Caps::npot_targets`]) the next powers of two, the
/// frame drawn in its lower-left corner.
pub(crate) fn texture_storage(caps: &Caps, (width, height): (u32, u32)) -> (u32, u32) {
    if caps.npot_targets {
        (width, height)
    } else {
        (width.next_power_of_two(), height.next_power_of_two())
    }
}

#[cfg(test)]
mod tests {
    use crate::gl::context::context_or_skip;
    use crate::gl::framebuffer::OffscreenTarget;
    use crate::gl::gbuffer::GBuffer;
    use crate::gl::multisample::MultisampleTarget;
    use crate::gl::{Device, EsVersion, GlError};

    /// A device whose textures and renderbuffers are limited to 64 and 48 pixels a side (far
    /// below the real driver's, which would allocate every size below).
    fn small_device(es: EsVersion) -> Option<(crate::gl::context::HeadlessContext, Device)> {
        let ctx = context_or_skip(es)?;
        let mut dev = Device::new(ctx.load_gl().unwrap(), es).unwrap();
        dev.caps_mut().max_texture_size = 64;
        dev.caps_mut().max_renderbuffer_size = 48;
        Some((ctx, dev))
    }

    /// `make`'s error names the limit, and the refused target left no object and no GL error.
    fn refused(dev: &Device, make: impl FnOnce() -> Result<(), GlError>, limit: &str) {
        let live = dev.live_objects();
        match make() {
            Err(e @ GlError::TooLarge { limit: named, .. }) => assert_eq!(named, limit, "{e}"),
            Err(GlError::Unsupported(msg)) if limit == "at least 1" => assert!(msg.contains(limit)),
            other => panic!("expected an error naming {limit}, got {other:?}"),
        }
        assert_eq!(dev.live_objects(), live);
        dev.check("the refused allocation").unwrap();
    }

    #[test]
    fn targets_past_the_texture_or_renderbuffer_limit_are_refused_by_name() {
        let Some((_ctx, dev)) = small_device(EsVersion::Es3) else {
            return;
        };
        let before = dev.live_objects();
        let gbuffer = |w, h| GBuffer::new(&dev, w, h, true).map(|mut g| g.destroy(&dev));
        let offscreen = |w, h| OffscreenTarget::new(&dev, w, h).map(|mut t| t.destroy(&dev));
        let msaa = |w, h| MultisampleTarget::new(&dev, w, h, 4).map(|mut t| t.destroy(&dev));
        refused(&dev, || gbuffer(65, 10), "GL_MAX_TEXTURE_SIZE");
        refused(&dev, || offscreen(10, 65), "GL_MAX_TEXTURE_SIZE");
        refused(&dev, || offscreen(49, 10), "GL_MAX_RENDERBUFFER_SIZE");
        refused(&dev, || msaa(10, 49), "GL_MAX_RENDERBUFFER_SIZE");
        refused(&dev, || gbuffer(0, 10), "at least 1");
        // At the limits every one is made.
        GBuffer::new(&dev, 64, 64, true).unwrap().destroy(&dev);
        OffscreenTarget::new(&dev, 48, 48).unwrap().destroy(&dev);
        MultisampleTarget::new(&dev, 48, 48, 4)
            .unwrap()
            .destroy(&dev);
        assert_eq!(dev.live_objects(), before);
    }
}
