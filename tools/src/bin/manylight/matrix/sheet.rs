//! The matrix's contact sheet: every cell's picture as a thumbnail.

use std::path::Path;

use manylight::methods::METHODS;
use serde_json::Value;

use super::table::{row_failure, row_labels};

/// Longest side of a contact sheet's thumbnail: the sheet holds every cell's at once, so full
/// pictures would make its memory grow with the frame's size.
pub(super) const THUMB_MAX: u32 = 512;

/// The picture in `file`, scaled down to fit [`THUMB_MAX`] (one full picture decoded at a time).
fn thumbnail(file: &Path) -> Option<image::RgbaImage> {
    let picture = image::open(file).ok()?;
    let fits = picture.width().max(picture.height()) <= THUMB_MAX;
    Some(
        if fits {
            picture
        } else {
            picture.thumbnail(THUMB_MAX, THUMB_MAX)
        }
        .to_rgba8(),
    )
}

pub(super) fn sheet(rows: &[Value], out: &Path) -> image::RgbaImage {
    let mut cells = Vec::new();
    for (row, (implementation, config)) in rows.iter().zip(row_labels(rows)) {
        let config = format!("{implementation}: {config}");
        if row["error"].is_string() {
            cells.push((vec![config, row_failure(row).to_string()], None));
            continue;
        }
        for m in row["methods"].as_array().into_iter().flatten() {
            let name = m["name"].as_str().unwrap_or("?");
            let thumb = m["image"].as_str().and_then(|f| thumbnail(&out.join(f)));
            let detail = match (m["support"]["status"].as_str(), m["max_abs"].as_f64()) {
                _ if m["error"].is_string() => "error".to_string(),
                (Some("unsupported"), _) => "unsupported".to_string(),
                (Some(status), Some(err)) => format!("{status}, max err {err:.0}/255"),
                (status, _) => status.unwrap_or("?").to_string(),
            };
            cells.push((vec![config.clone(), format!("{name}: {detail}")], thumb));
        }
    }
    manylight_tools::sheet::contact_sheet(&cells, METHODS.len())
}
