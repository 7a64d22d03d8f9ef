//! The pictures of `manylight bench`: heat maps, difference images and the reference.

use manylight::EsVersion;
use manylight_tools::report::{self, Pictures};

use super::measure::{Baseline, Measured};

/// The scene, ES version and light count a set of pictures shows.
pub(super) struct Workload<'a> {
    pub(super) scene: &'a str,
    pub(super) es: EsVersion,
    pub(super) lights: usize,
}

/// How far difference images amplify: an error of this many 8-bit steps or more gets the top
/// colour (×32).
const DIFF_FULL_SCALE: u8 = 8;

/// Heatmaps of every method and of the lower bound, each method's difference from the
/// reference, and the reference, for one scene's picture workload (its knobs' light count):
/// from the images and counts its default configurations already measured. Returns the file
/// names for the report.
pub(super) fn write_pictures(
    at: &Workload,
    measured: &[(String, Measured)],
    base: &Baseline,
    out: &std::path::Path,
) -> Result<Pictures, Box<dyn std::error::Error>> {
    use manylight_tools::heatmap::{self, Scale};
    use manylight_tools::output::save_png;
    std::fs::create_dir_all(out)?;
    let (scene, es, lights) = (at.scene, format!("{}.0", at.es.major()), at.lights);
    let maps = std::iter::once(("lower-bound", &base.bound))
        .chain(measured.iter().map(|(name, m)| (name.as_str(), &m.evals)));
    // One colour scale for all the maps, so they compare at a glance. It must reach forward's
    // count (every light at every pixel) or forward's map clips to one flat colour; but on a
    // linear scale that high, the culling methods' few to few hundred evaluations would all
    // be the same dark purple. A log scale does both: forward's count is the top, and 3, 30
    // and 300 evaluations are equal steps below it.
    let scale = Scale::Log(maps.clone().map(|(_, c)| c.max()).max().unwrap_or(1));
    let mut pictures = Pictures {
        scene: scene.to_string(),
        es: es.clone(),
        lights,
        reference: report::reference_file(scene, &es),
        ..Pictures::default()
    };
    for (name, c) in maps {
        let title = format!(
            "{name}: {:.1} light evaluations per pixel ({scene}, ES {es}, {lights} lights).\n\
             Colour: evaluations at each pixel on a log scale shared by all maps of this \
             scene and ES version, up to the largest ({}), so none clips; dark grey: \
             background.",
            c.mean(),
            scale.max()
        );
        let file = report::heatmap_file(scene, &es, name);
        let map = heatmap::heatmap(&c.counts, &c.covered, c.width, c.height, scale, &title);
        save_png(&out.join(&file), &map)?;
        pictures.heatmaps.push((name.to_string(), file));
    }
    for (name, m) in measured {
        let what = format!(
            "{name} vs reference (forward, all lights, highp): {scene}, ES {es}, {lights} lights."
        );
        let file = report::diff_file(scene, &es, name);
        let diff = heatmap::diff_image(&base.reference, &m.image, DIFF_FULL_SCALE, &what);
        save_png(&out.join(&file), &diff)?;
        pictures.diffs.push((name.clone(), file));
    }
    save_png(&out.join(&pictures.reference), &base.reference)?;
    Ok(pictures)
}
