//! The window side of `manylight view`: a winit window, an OpenGL ES context and window
//! surface from glutin over EGL, and the [`Renderer`] on them.
//!
//! EGL only (X11 or Wayland here, the same code on Android): GLX cannot create ES contexts.
//! ES 3.0 is asked for first and ES 2.0 taken when the driver has no ES 3.0 config or context,
//! unless the user named a version. The config needs a depth buffer, because every method
//! draws a depth prepass into the bound (here: the default) framebuffer.
//!
//! The few `unsafe` calls are glutin's and glow's FFI entry points; each says why it holds.

use std::ffi::CStr;
use std::num::NonZeroU32;

use glow::HasContext;
use glutin::config::{Api, Config, ConfigTemplateBuilder, GlConfig};
use glutin::context::{ContextApi, ContextAttributesBuilder, NotCurrentContext, Version};
use glutin::context::{NotCurrentGlContext, PossiblyCurrentContext};
use glutin::display::{Display, DisplayApiPreference, GlDisplay};
use glutin::surface::{GlSurface, Surface, SurfaceAttributesBuilder, SwapInterval, WindowSurface};
use manylight::{EsVersion, Renderer};
use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::Window;

/// Renderer, context, surface and window. Fields drop in declaration order, so the surface
/// goes before the window it draws to.
pub struct Gfx {
    /// `None` once destroyed (it must be destroyed while the context is current).
    pub renderer: Option<Renderer>,
    /// A second function table for the viewer's own GL calls (the read-back).
    gl: glow::Context,
    surface: Surface<WindowSurface>,
    context: PossiblyCurrentContext,
    /// The window.
    pub window: Window,
    /// The feature level the context was made for (and the renderer restricted to).
    pub es: EsVersion,
}

impl Gfx {
    /// Opens the EGL display, makes a context (`es`, or ES 3.0 then ES 2.0 when `None`), a
    /// `size` window and its surface, and a renderer on them.
    pub fn create(
        event_loop: &ActiveEventLoop,
        title: &str,
        size: (u32, u32),
        es: Option<EsVersion>,
    ) -> Result<Gfx, String> {
        let raw_display = event_loop
            .display_handle()
            .map_err(|e| format!("no display handle: {e}"))?
            .as_raw();
        // SAFETY: the handle comes from the running event loop, which outlives the display
        // (the display is dropped with `Gfx`, at the latest when the loop exits).
        let display = unsafe { Display::new(raw_display, DisplayApiPreference::Egl) }
            .map_err(|e| format!("cannot open an EGL display: {e}"))?;
        let wanted: &[EsVersion] = match es {
            Some(es) => &[es],
            None => &[EsVersion::Es3, EsVersion::Es2],
        };
        let mut failures = Vec::new();
        let mut made = None;
        for &es in wanted {
            match create_context(&display, es) {
                Ok(c) => {
                    made = Some((es, c));
                    break;
                }
                Err(e) => failures.push(format!("{es}: {e}")),
            }
        }
        let Some((es, (config, context))) = made else {
            return Err(format!(
                "cannot create an OpenGL ES context: {}",
                failures.join("; ")
            ));
        };
        if !failures.is_empty() {
            eprintln!("warning: falling back to {es} ({})", failures.join("; "));
        }
        let attributes = Window::default_attributes()
            .with_title(title)
            .with_inner_size(PhysicalSize::new(size.0, size.1));
        // Picks the X11 visual matching the config.
        let window = glutin_winit::finalize_window(event_loop, attributes, &config)
            .map_err(|e| format!("cannot create a window: {e}"))?;
        let inner = window.inner_size();
        let handle = window
            .window_handle()
            .map_err(|e| format!("no window handle: {e}"))?
            .as_raw();
        let surface_attributes = SurfaceAttributesBuilder::<WindowSurface>::new().build(
            handle,
            NonZeroU32::new(inner.width).unwrap_or(NonZeroU32::MIN),
            NonZeroU32::new(inner.height).unwrap_or(NonZeroU32::MIN),
        );
        // SAFETY: the window outlives the surface (`Gfx` drops the surface first).
        let surface = unsafe { display.create_window_surface(&config, &surface_attributes) }
            .map_err(|e| format!("cannot create a window surface: {e}"))?;
        let context = context
            .make_current(&surface)
            .map_err(|e| format!("cannot make the context current: {e}"))?;
        if let Err(e) = surface.set_swap_interval(&context, SwapInterval::Wait(NonZeroU32::MIN)) {
            log::info!("no vsync: {e}");
        }
        let renderer = Renderer::new(load_gl(&display), es).map_err(|e| e.to_string())?;
        Ok(Gfx {
            renderer: Some(renderer),
            gl: load_gl(&display),
            surface,
            context,
            window,
            es,
        })
    }

    /// Follows a window resize (needed on Wayland; X11 surfaces follow by themselves).
    pub fn resize(&self, size: PhysicalSize<u32>) {
        if let (Some(w), Some(h)) = (NonZeroU32::new(size.width), NonZeroU32::new(size.height)) {
            self.surface.resize(&self.context, w, h);
        }
    }

    /// Presents the frame.
    pub fn swap(&self) -> Result<(), String> {
        self.surface
            .swap_buffers(&self.context)
            .map_err(|e| format!("eglSwapBuffers failed: {e}"))
    }

    /// Reads the window's back buffer (the finished frame, before [`Gfx::swap`]), top row
    /// first, as an opaque image.
    pub fn read_back(&self, size: PhysicalSize<u32>) -> Result<image::RgbaImage, String> {
        let (w, h) = (size.width as usize, size.height as usize);
        let mut pixels = vec![0u8; w * h * 4];
        // SAFETY: `pixels` holds exactly w×h RGBA8 texels, and rows of RGBA8 are already
        // 4-byte aligned, so GL writes inside the slice.
        let error = unsafe {
            self.gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            self.gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
            self.gl.read_pixels(
                0,
                0,
                w as i32,
                h as i32,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelPackData::Slice(Some(&mut pixels)),
            );
            self.gl.get_error()
        };
        if error != glow::NO_ERROR {
            return Err(format!("glReadPixels failed: GL error 0x{error:04X}"));
        }
        // GL's rows run bottom-up; a window is opaque, whatever its alpha channel holds.
        let mut flipped = Vec::with_capacity(pixels.len());
        for row in pixels.chunks_exact(w * 4).rev() {
            flipped.extend(row.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2], 255]));
        }
        image::RgbaImage::from_raw(size.width, size.height, flipped)
            .ok_or_else(|| "read-back buffer has the wrong size".to_string())
    }
}

/// A window-capable config with a depth buffer and a not-yet-current context, both for `es`.
fn create_context(display: &Display, es: EsVersion) -> Result<(Config, NotCurrentContext), String> {
    let api = match es {
        EsVersion::Es2 => Api::GLES2,
        EsVersion::Es3 => Api::GLES3,
    };
    let template = ConfigTemplateBuilder::new()
        .with_api(api)
        .with_alpha_size(0)
        .with_depth_size(16)
        .build();
    // SAFETY: only queries the display's configs.
    let configs = unsafe { display.find_configs(template) }.map_err(|e| e.to_string())?;
    // Prefer no multisampling, then a 24-bit depth buffer.
    let config = configs
        .max_by_key(|c| (c.num_samples() == 0, c.depth_size().min(24)))
        .ok_or_else(|| "no EGL config with a depth buffer renders to windows".to_string())?;
    let attributes = ContextAttributesBuilder::new()
        .with_context_api(ContextApi::Gles(Some(Version::new(es.major() as u8, 0))))
        .build(None);
    // SAFETY: a plain context, shared with nothing and not tied to a window handle.
    let context = unsafe { display.create_context(&config, &attributes) }
        .map_err(|e| format!("eglCreateContext: {e}"))?;
    Ok((config, context))
}

/// A glow function table for the context current on this thread.
fn load_gl(display: &Display) -> glow::Context {
    // SAFETY: glutin returns EGL's entry points (or null); glow only stores them, and the
    // context they belong to stays current for as long as the viewer uses them.
    unsafe {
        glow::Context::from_loader_function_cstr(|name: &CStr| display.get_proc_address(name))
    }
}
