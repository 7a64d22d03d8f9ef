//! What `manylight bench` checks before its first row: a bad scene, method, output folder or
//! context fails the sweep at once, not after the rows before it were measured.

use manylight::gl::HeadlessContext;
use manylight::scene::shown;
use manylight::Renderer;
use manylight_tools::report;

use super::plan::{scene_name, Plan};
use super::{load_bench_scene, BenchArgs};

/// Checks the methods' names, the output folder and the report's files in it, the scenes'
/// labels, every scene (loaded once) and each ES version's context and renderer. Returns the
/// report's FIFOs held open, to be dropped after the report is written (their readers would
/// otherwise see their end now).
pub(super) fn check_before_rendering(
    args: &BenchArgs,
    plan: &Plan,
) -> Result<Vec<std::fs::File>, Box<dyn std::error::Error>> {
    // What can be checked before any rendering is: the methods' names, the output folder.
    for method in &plan.methods {
        manylight::methods::find(method)?;
    }
    std::fs::create_dir_all(&args.out).map_err(|e| {
        format!(
            "cannot create the output folder {}: {e}",
            shown::path(&args.out)
        )
    })?;
    let probe = args.out.join(".manylight-write-test");
    std::fs::write(&probe, b"")
        .and_then(|()| std::fs::remove_file(&probe))
        .map_err(|e| format!("cannot write into {}: {e}", shown::path(&args.out)))?;
    // The report's own files, where something is in the way (a folder of that name, a file
    // that cannot be written): found after the whole sweep before.
    let mut held = Vec::new();
    for name in ["report.json", "report.md"] {
        let path = args.out.join(name);
        let blocked = match std::fs::symlink_metadata(&path) {
            Ok(meta) if meta.is_dir() => Some("a folder is in the way".to_string()),
            Ok(_) => match manylight_tools::output::check_writable_later(&path) {
                Ok(fifo) => {
                    held.extend(fifo);
                    None
                }
                Err(e) => Some(e.to_string()),
            },
            Err(_) => None,
        };
        if let Some(why) = blocked {
            return Err(format!("cannot write {}: {why}", shown::path(&path)).into());
        }
    }
    // Rows, pictures and chart series are named by the scene's file stem: two alike would
    // overwrite each other's pictures and merge into one series.
    let mut labels = std::collections::HashMap::new();
    for spec in &plan.scenes {
        let label = report::file_tag(&scene_name(spec));
        if let Some(first) = labels.insert(label.clone(), spec) {
            return Err(format!(
                "--scenes names `{first}` and `{spec}`, which both report as `{label}`: their \
                 rows and pictures would overwrite each other (give each its own file name)"
            )
            .into());
        }
    }
    // Every scene loads once here, so a bad one fails the sweep before its first row, not
    // after the scenes before it were measured.
    let first_count = plan.lights.first().copied().unwrap_or(0);
    for spec in &plan.scenes {
        load_bench_scene(spec, first_count, args)?;
    }
    // And each ES version's context and renderer once (a driver capped at ES 2.0 refuses an
    // ES 3.0 context, or gives a 2.0 one the renderer refuses): here, not after the ES 2.0 rows.
    for &es in &plan.es {
        let ctx = HeadlessContext::new(es)?;
        Renderer::new(ctx.load_gl()?, es)?.destroy();
    }
    Ok(held)
}
