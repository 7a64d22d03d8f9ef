//! An MTL texture statement's options (`map_Kd -clamp on -s 2 2 1 wood grain.png`): the ones
//! the OBJ material applies, and the file name after them (which may hold spaces).
//!
//! Options take the arguments the MTL format gives them; a number option's optional arguments
//! are taken while they read as numbers, but never the statement's last word, which is
//! always left for the file name. Parsing stops at the first word that is not a known option
//! with its arguments: the rest is the file name (the loader then also tries the last word
//! alone, as names written after options it does not know were found before).

use glam::Vec2;

use crate::scene::surface_maps::TextureTransform;

/// What a texture statement says beyond its file.
#[derive(Debug, PartialEq)]
pub(super) struct MapStatement<'a> {
    /// The file named after the options, as written (trimmed).
    pub file: &'a str,
    /// `-clamp on`: one copy of the image, not repeated.
    pub clamp: bool,
    /// `-o u v`: added to the texture coordinates (OBJ's, v up) after `scale`.
    pub offset: [f64; 2],
    /// `-s u v`: multiplies the texture coordinates.
    pub scale: [f64; 2],
    /// Options that change the picture but are not applied, each once, in order.
    pub unapplied: Vec<&'static str>,
}

/// How an option's arguments are read.
#[derive(Clone, Copy)]
enum Arguments {
    /// `on` or `off`.
    Switch,
    /// From `least` to `most` numbers.
    Numbers { least: usize, most: usize },
    /// One word (`-imfchan r`, `-type sphere`).
    Word,
}

/// The options of the MTL format's texture statements and their arguments.
const OPTIONS: [(&str, Arguments); 13] = [
    ("-blendu", Arguments::Switch),
    ("-blendv", Arguments::Switch),
    ("-cc", Arguments::Switch),
    ("-clamp", Arguments::Switch),
    ("-bm", Arguments::Numbers { least: 1, most: 1 }),
    ("-boost", Arguments::Numbers { least: 1, most: 1 }),
    ("-mm", Arguments::Numbers { least: 1, most: 2 }),
    ("-o", Arguments::Numbers { least: 1, most: 3 }),
    ("-s", Arguments::Numbers { least: 1, most: 3 }),
    ("-t", Arguments::Numbers { least: 1, most: 3 }),
    ("-texres", Arguments::Numbers { least: 1, most: 1 }),
    ("-imfchan", Arguments::Word),
    ("-type", Arguments::Word),
];

impl<'a> MapStatement<'a> {
    /// Reads a texture statement's value (what follows `map_Kd`).
    pub fn parse(value: &'a str) -> MapStatement<'a> {
        let mut statement = MapStatement {
            file: value.trim(),
            clamp: false,
            offset: [0.0; 2],
            scale: [1.0; 2],
            unapplied: Vec::new(),
        };
        let mut rest = value.trim();
        while let Some((name, kind)) = OPTIONS.iter().find(|(n, _)| first_word(rest).0 == *n) {
            let mut after = first_word(rest).1;
            let mut numbers = Vec::new();
            let mut switch = None;
            let read = match *kind {
                Arguments::Switch => {
                    let (word, next) = first_word(after);
                    switch = match word.to_ascii_lowercase().as_str() {
                        "on" => Some(true),
                        "off" => Some(false),
                        _ => None,
                    };
                    after = next;
                    switch.is_some()
                }
                Arguments::Numbers { least, most } => {
                    while numbers.len() < most {
                        let (word, next) = first_word(after);
                        match word.parse::<f64>() {
                            Ok(n) if !next.is_empty() => numbers.push(n),
                            _ => break,
                        }
                        after = next;
                    }
                    numbers.len() >= least
                }
                Arguments::Word => {
                    after = first_word(after).1;
                    true
                }
            };
            // Never the last word: it is the file's name.
            if !read || after.is_empty() {
                break;
            }
            statement.note(name, switch, &numbers);
            rest = after;
        }
        statement.file = rest;
        statement
    }

    /// Records option `name`'s effect: its `switch` or its `numbers`.
    fn note(&mut self, name: &'static str, switch: Option<bool>, numbers: &[f64]) {
        let or = |i: usize, default: f64| numbers.get(i).copied().unwrap_or(default);
        let changes_picture = match name {
            "-clamp" => {
                self.clamp = switch == Some(true);
                false
            }
            "-o" => {
                self.offset = [or(0, 0.0), or(1, 0.0)];
                false
            }
            "-s" => {
                self.scale = [or(0, 1.0), or(1, 1.0)];
                false
            }
            "-mm" => or(0, 0.0) != 0.0 || or(1, 1.0) != 1.0,
            "-t" => numbers.iter().any(|&n| n != 0.0),
            "-imfchan" => true,
            // Blending, colour correction, sharpness, resolution, bump strength: nothing a
            // single diffuse image shows here.
            _ => false,
        };
        if changes_picture && !self.unapplied.contains(&name) {
            self.unapplied.push(name);
        }
    }

    /// `-o` and `-s` as the base colour's [`TextureTransform`] in the coordinates the loader
    /// keeps (`v` flipped, `t = 1 − v`): `u' = su·u + ou`, and `t' = 1 − (sv·v + ov)` is
    /// `sv·t + (1 − sv − ov)`. `None` when one is not usable (not finite, or past the
    /// coordinate limit).
    pub fn transform(&self) -> Option<TextureTransform> {
        let [ou, ov] = self.offset;
        let [su, sv] = self.scale;
        let transform = TextureTransform {
            offset: Vec2::new(ou as f32, (1.0 - sv - ov) as f32),
            rotation: 0.0,
            scale: Vec2::new(su as f32, sv as f32),
            uv_set: 0,
        };
        transform.is_usable().then_some(transform)
    }
}

/// The first whitespace-separated word of `text` (trimmed at its start) and what follows it,
/// trimmed at its start.
fn first_word(text: &str) -> (&str, &str) {
    let text = text.trim_start();
    let end = text.find(char::is_whitespace).unwrap_or(text.len());
    let (word, rest) = text.split_at(end);
    (word, rest.trim_start())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    #[test]
    fn the_options_are_read_and_the_rest_is_the_file_name() {
        let s = MapStatement::parse("  -clamp on -s 2 3 1 -o 0.25 0.5 wood grain.png ");
        assert_eq!(s.file, "wood grain.png");
        assert!(s.clamp);
        assert_eq!(s.scale, [2.0, 3.0]);
        assert_eq!(s.offset, [0.25, 0.5]);
        assert!(s.unapplied.is_empty());
        let plain = MapStatement::parse("textures\\Brick.png");
        assert_eq!(plain.file, "textures\\Brick.png");
        assert!(!plain.clamp);
        assert_eq!((plain.scale, plain.offset), ([1.0; 2], [0.0; 2]));
    }

    #[test]
    fn optional_numbers_default_and_the_last_word_is_never_an_argument() {
        let s = MapStatement::parse("-s 4 7");
        assert_eq!((s.scale, s.file), ([4.0, 1.0], "7"));
        let s = MapStatement::parse("-o 0.5 -clamp off -bm 0.2 a.png");
        assert_eq!((s.offset, s.clamp, s.file), ([0.5, 0.0], false, "a.png"));
        // An option with nothing after it is the name (the loader tries the last word too).
        assert_eq!(MapStatement::parse("-clamp on").file, "-clamp on");
    }

    #[test]
    fn a_malformed_or_unknown_option_ends_the_options() {
        let s = MapStatement::parse("-clamp maybe a.png");
        assert_eq!((s.file, s.clamp), ("-clamp maybe a.png", false));
        let s = MapStatement::parse("-s 2 -foo 1 a.png");
        assert_eq!((s.file, s.scale), ("-foo 1 a.png", [2.0, 1.0]));
        assert_eq!(MapStatement::parse("-s x a.png").file, "-s x a.png");
    }

    #[test]
    fn options_that_change_the_picture_unapplied_are_listed_once() {
        let s = MapStatement::parse("-mm 0.2 0.8 -t 0 0 0 -imfchan l -mm 0 2 -cc on a.png");
        assert_eq!(s.unapplied, ["-mm", "-imfchan"]);
        assert_eq!(s.file, "a.png");
        assert!(MapStatement::parse("-mm 0 1 -t 0 a.png")
            .unapplied
            .is_empty());
    }

    #[test]
    fn the_transform_maps_flipped_coordinates_as_the_options_map_obj_ones() {
        let s = MapStatement::parse("-s 2 3 -o 0.25 -0.5 a.png");
        let t = s.transform().unwrap();
        for (u, v) in [(0.0, 0.0), (1.0, 0.0), (0.3, 0.9), (-1.5, 2.25)] {
            let kept = t.apply(DVec2::new(u, 1.0 - v));
            let (u2, v2) = (2.0 * u + 0.25, 3.0 * v - 0.5);
            assert!((kept - DVec2::new(u2, 1.0 - v2)).abs().max_element() < 1e-6);
        }
        assert_eq!(
            MapStatement::parse("a.png").transform(),
            Some(TextureTransform::IDENTITY)
        );
        for bad in ["-s nan 1 a.png", "-o 1e30 a.png", "-s inf a.png"] {
            assert_eq!(MapStatement::parse(bad).transform(), None, "{bad}");
        }
    }
}
