//! Tests of the matrix's rows, table, sheet and cells' output.

use super::child::{cell_error, cell_row};
use super::configs::CONFIGS;
use super::sheet::{sheet, THUMB_MAX};
use super::table::markdown;
use super::{labelled_row, name_failed_rows};
use serde_json::json;

/// The system's libraries need not be Mesa (a device farm's driver): there every row of a
/// Mesa switch is unavailable, not a pass of the unrestricted driver under its name, and
/// every other row stays as its cell made it.
#[test]
fn every_mesa_switch_row_on_another_implementation_is_unavailable() {
    let swiftshader = json!({"implementation": "SwiftShader", "float_textures": true,
        "gl_version": "OpenGL ES 3.2 SwiftShader", "renderer": "Google SwiftShader",
        "methods": [{"name": "forward", "max_abs_vs_forward": 0}]});
    for config in CONFIGS {
        let row = labelled_row(config, swiftshader.clone(), "system");
        if config.env.is_empty() {
            assert!(row["error"].is_null(), "{}: {row}", config.name);
            assert_eq!(row["methods"], swiftshader["methods"], "{}", config.name);
        } else {
            assert_eq!(row["refused"], true, "{}: {row}", config.name);
            assert_eq!(row["methods"], json!([]), "{}", config.name);
            assert!(row["error"].as_str().unwrap().contains("not applied"));
        }
    }
}

/// A row whose context failed (an llvmpipe row at a size it cannot take) is named after
/// its group's rows on the same driver, never after softpipe's, which succeeded.
#[test]
fn a_failed_row_takes_its_own_drivers_name() {
    let softpipe = json!({"implementation": "Mesa softpipe", "config": "ES 3.x on softpipe",
        "env": ["GALLIUM_DRIVER=softpipe"]});
    let failed = json!({"implementation": null, "config": "ES 3.0", "env": []});
    let mut rows = [softpipe.clone(), failed.clone()];
    name_failed_rows(&mut rows, "system");
    assert_eq!(rows[1]["implementation"], "system");
    let llvmpipe = json!({"implementation": "Mesa llvmpipe", "config": "ES 2.0", "env": []});
    let mut rows = [softpipe, llvmpipe.clone(), failed];
    name_failed_rows(&mut rows, "system");
    assert_eq!(rows[2]["implementation"], "Mesa llvmpipe");
    assert_eq!(rows[0]["implementation"], "Mesa softpipe");
    // Nor the other way round: a failed softpipe row is not llvmpipe's.
    let failed_softpipe = json!({"implementation": null, "config": "ES 3.x on softpipe",
        "env": ["GALLIUM_DRIVER=softpipe"]});
    let mut rows = [llvmpipe, failed_softpipe];
    name_failed_rows(&mut rows, "system");
    assert_eq!(rows[1]["implementation"], "system");
}

/// Large pictures go on the sheet scaled down to fit [`THUMB_MAX`], their shape kept; small
/// ones as they are.
#[test]
fn the_sheet_holds_large_pictures_as_thumbnails() {
    let dir = tempfile::tempdir().unwrap();
    let picture = image::RgbaImage::from_pixel(2048, 1152, image::Rgba([200, 0, 0, 255]));
    picture.save(dir.path().join("big.png")).unwrap();
    let small = image::RgbaImage::from_pixel(64, 36, image::Rgba([0, 200, 0, 255]));
    small.save(dir.path().join("small.png")).unwrap();
    let rows = [
        json!({"implementation": "Mesa llvmpipe", "config": "ES 3.0",
        "methods": [{"name": "forward", "image": "big.png"},
                    {"name": "clustered", "image": "small.png"}]}),
    ];
    let sheet = sheet(&rows, dir.path());
    assert!(sheet.height() < THUMB_MAX + 100, "{:?}", sheet.dimensions());
    let red = |p: &&image::Rgba<u8>| p.0 == [200, 0, 0, 255];
    let green = |p: &&image::Rgba<u8>| p.0 == [0, 200, 0, 255];
    assert_eq!(sheet.pixels().filter(red).count(), 512 * 288);
    assert_eq!(sheet.pixels().filter(green).count(), 64 * 36);
}

/// Two implementations of one family (two Mesa builds) are told apart by their folders;
/// auto's row says what it ran.
#[test]
fn the_table_tells_same_family_implementations_apart_and_says_what_auto_ran() {
    let row = |lib: &str| {
        json!({"implementation": "Mesa llvmpipe", "gles_lib": lib, "config": "ES 3.0",
            "gl_version": "3.2", "max_samples": 4,
            "methods": [{"name": "auto", "support": {"status": "supported"},
                "auto_choice": "forward", "max_abs_vs_forward": 0}]})
    };
    let table = markdown(&[row("system"), row("/opt/mesa")]);
    assert!(table.contains("| Mesa llvmpipe (system) |"), "{table}");
    assert!(table.contains("| Mesa llvmpipe (/opt/mesa) |"), "{table}");
    assert!(table.contains("| auto → forward |"), "{table}");
    let alone = markdown(&[row("system")]);
    assert!(alone.contains("| Mesa llvmpipe | ES 3.0 |"), "{alone}");
}
use std::os::unix::process::ExitStatusExt;
use std::process::{ExitStatus, Output};

#[test]
fn a_cell_error_is_one_line_without_the_warnings_before_it() {
    let stderr = b"[WARN  manylight::renderer] fragment mediump\nerror: lights[0]: too far\n";
    let failed = ExitStatus::from_raw(1 << 8);
    assert_eq!(cell_error(stderr, failed), "lights[0]: too far");
    assert_eq!(
        cell_error(b"[WARN  x] slow\nthread panicked\nboom\n\n", failed),
        "the cell stopped (exit status: 1); its last line: boom"
    );
    assert_eq!(
        cell_error(b"", ExitStatus::from_raw(0)),
        "the cell printed no result"
    );
}

/// A driver's own line on stdout (Mesa's, under `MESA_EXTENSION_OVERRIDE`) does not hide
/// the row printed before it.
#[test]
fn a_cells_row_is_its_last_json_line_whatever_follows() {
    let output = Output {
        status: ExitStatus::from_raw(0),
        stdout: b"{\"es\":\"2\",\"methods\":[]}\nWarning: extension 'X' cannot be disabled\n"
            .to_vec(),
        stderr: Vec::new(),
    };
    let row = cell_row(&output);
    assert_eq!(row["es"], "2", "{row}");
    assert!(row["error"].is_null(), "{row}");
    let failed = Output {
        status: ExitStatus::from_raw(1 << 8),
        ..output
    };
    assert!(cell_row(&failed)["error"].is_string());
}
