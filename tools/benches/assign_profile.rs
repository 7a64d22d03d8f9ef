//! Development aid: one workload assigned repeatedly with reused buffers (for profilers): `cargo
//! bench --bench assign_profile -- LIGHTS [REPEATS] [--fine | --hd | --size=WxH --grid=PX]` (or
//! run its binary under a profiler); `--fine` takes the fine grid of
//! [`AssignWorkload::fine_grid`], `--hd` the default view at 1280×720 on a fixed grid of 16-px
//! cells ([`AssignWorkload::renderer_grid`], near the renderer's `--size 1280x720 --grid 16`),
//! `--size` and `--grid` any such fixed grid (1280x720 and 16 px unless given).
use manylight::cluster::assign::Assigner;
use manylight_tools::workload::AssignWorkload;

fn main() {
    let mut args = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .map(|a| a.parse::<usize>().ok());
    let count = args.next().flatten().unwrap_or(65_536);
    let repeats = args.next().flatten().unwrap_or(20);
    let flag = |name: &str| std::env::args().any(|a| a == name);
    let value = |name: &str| {
        let prefix = format!("--{name}=");
        std::env::args().find_map(|a| a.strip_prefix(&prefix).map(str::to_string))
    };
    let fail = |what: &str| -> ! {
        eprintln!("assign_profile: {what}");
        std::process::exit(2)
    };
    let size = value("size").map(|s| {
        let parsed = s.split_once('x').map(|(w, h)| (w.parse(), h.parse()));
        match parsed {
            Some((Ok(w), Ok(h))) if w > 0 && h > 0 => (w, h),
            _ => fail("--size wants WIDTHxHEIGHT, both above 0"),
        }
    });
    let grid = value("grid").map(|px| match px.parse::<f64>() {
        Ok(px) if px.is_finite() && px >= 1.0 => px,
        _ => fail("--grid wants a cell footprint of 1 pixel or more"),
    });
    let w = if flag("--fine") {
        AssignWorkload::fine_grid(count, 1)
    } else if flag("--hd") || size.is_some() || grid.is_some() {
        let size = size.unwrap_or((1280, 720));
        AssignWorkload::renderer_grid(count, 1, size, grid.unwrap_or(16.0))
    } else {
        AssignWorkload::default_view(count, 1)
    };
    let mut assigner = Assigner::new();
    let mut total = 0;
    for _ in 0..repeats {
        total += w.assign_with(&mut assigner).indices.len();
    }
    println!("{total}");
}
