//! The size of the bound framebuffer object's colour buffer, where GL can say it: a
//! renderbuffer's always, a texture level's where `glGetTexLevelParameteriv` exists (ES 3.1,
//! desktop GL). A window surface's (the default framebuffer) is EGL's to say, and not asked.
#![allow(unsafe_code)]

use glow::HasContext;

use super::Device;

impl Device {
    /// The colour attachment 0 of the bound framebuffer `target` as `(width, height)`, or
    /// `None` where GL cannot say (the default framebuffer, a texture on ES 3.0 or 2.0). Leaves
    /// the bindings it used as they were.
    pub(crate) fn bound_color_size(&self, target: Option<glow::Framebuffer>) -> Option<(u32, u32)> {
        target?;
        let gl = &self.gl;
        let param = |pname| unsafe {
            gl.get_framebuffer_attachment_parameter_i32(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                pname,
            )
        };
        let kind = param(glow::FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) as u32;
        // Nothing attached: its name is no query on ES 2.0 (`GL_INVALID_ENUM`).
        if kind == glow::NONE {
            self.drain_errors();
            return None;
        }
        let name =
            std::num::NonZeroU32::new(param(glow::FRAMEBUFFER_ATTACHMENT_OBJECT_NAME) as u32);
        let size = match (kind, name) {
            (glow::RENDERBUFFER, Some(name)) => unsafe {
                let before = gl.get_parameter_i32(glow::RENDERBUFFER_BINDING);
                gl.bind_renderbuffer(glow::RENDERBUFFER, Some(glow::NativeRenderbuffer(name)));
                let w =
                    gl.get_renderbuffer_parameter_i32(glow::RENDERBUFFER, glow::RENDERBUFFER_WIDTH);
                let h = gl
                    .get_renderbuffer_parameter_i32(glow::RENDERBUFFER, glow::RENDERBUFFER_HEIGHT);
                gl.bind_renderbuffer(glow::RENDERBUFFER, renderbuffer(before));
                (w, h)
            },
            (glow::TEXTURE, Some(name)) if self.has_texture_level_queries() => {
                let level = param(glow::FRAMEBUFFER_ATTACHMENT_TEXTURE_LEVEL);
                let face = param(glow::FRAMEBUFFER_ATTACHMENT_TEXTURE_CUBE_MAP_FACE) as u32;
                if self.drain_errors() != glow::NO_ERROR {
                    return None;
                }
                self.texture_level_size(glow::NativeTexture(name), level, face)?
            }
            _ => {
                // A driver's error on a query here is not the frame's.
                self.drain_errors();
                return None;
            }
        };
        let answered = self.drain_errors() == glow::NO_ERROR;
        match size {
            (w, h) if answered && w > 0 && h > 0 => Some((w as u32, h as u32)),
            _ => None,
        }
    }

    /// The size of `texture`'s `level` (of its cube face `face`, where not 0). Its target is
    /// not asked of the attachment: each one a colour buffer may be a texture of (a 2D texture,
    /// a layer of a 3D or array one, a multisampled one) is tried in turn, since binding a
    /// texture to another target than its own is a GL error and binds nothing.
    fn texture_level_size(
        &self,
        texture: glow::Texture,
        level: i32,
        face: u32,
    ) -> Option<(i32, i32)> {
        let gl = &self.gl;
        let targets: &[(u32, u32)] = if face != 0 {
            &[(glow::TEXTURE_CUBE_MAP, glow::TEXTURE_BINDING_CUBE_MAP)]
        } else {
            &[
                (glow::TEXTURE_2D, glow::TEXTURE_BINDING_2D),
                (glow::TEXTURE_2D_ARRAY, glow::TEXTURE_BINDING_2D_ARRAY),
                (glow::TEXTURE_3D, glow::TEXTURE_BINDING_3D),
                (
                    glow::TEXTURE_2D_MULTISAMPLE,
                    glow::TEXTURE_BINDING_2D_MULTISAMPLE,
                ),
            ]
        };
        targets.iter().find_map(|&(target, binding)| unsafe {
            let before = gl.get_parameter_i32(binding);
            gl.bind_texture(target, Some(texture));
            if self.drain_errors() != glow::NO_ERROR {
                return None;
            }
            let query = if face != 0 { face } else { target };
            let w = gl.get_tex_level_parameter_i32(query, level, glow::TEXTURE_WIDTH);
            let h = gl.get_tex_level_parameter_i32(query, level, glow::TEXTURE_HEIGHT);
            gl.bind_texture(target, texture_binding(before));
            Some((w, h))
        })
    }

    /// Whether `glGetTexLevelParameteriv` exists: ES 3.1 and desktop GL.
    fn has_texture_level_queries(&self) -> bool {
        let caps = self.caps();
        let number = |n: Option<&str>| n.and_then(|n| n.parse::<u32>().ok()).unwrap_or(0);
        let mut version = caps.context_version.split('.');
        let (major, minor) = (number(version.next()), number(version.next()));
        caps.desktop || (major, minor) >= (3, 1)
    }
}

fn renderbuffer(binding: i32) -> Option<glow::Renderbuffer> {
    std::num::NonZeroU32::new(binding as u32).map(glow::NativeRenderbuffer)
}

fn texture_binding(binding: i32) -> Option<glow::Texture> {
    std::num::NonZeroU32::new(binding as u32).map(glow::NativeTexture)
}
