//! Tests of the outputs: replacement, deferral, long names, links, full devices, identity.

use super::memory::ALLOCATABLE;
use super::temporaries::NAME_MAX;
use super::*;

#[test]
fn a_complete_file_replaces_the_old_one_and_keeps_its_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let path = dir.join("a.json");
    std::fs::write(&path, "old").unwrap();
    std::fs::set_permissions(&path, Permissions::from_mode(0o640)).unwrap();
    write_bytes(&path, b"new").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"new");
    let mode = std::fs::metadata(&path).unwrap().permissions().mode();
    assert_eq!(mode & 0o777, 0o640);
    assert_eq!(
        std::fs::read_dir(dir).unwrap().count(),
        1,
        "a temporary file is left"
    );
}

/// A picture whose encoding cannot be allocated is an error naming the file, the old file
/// whole and no temporary left.
#[test]
fn a_picture_whose_encoding_cannot_be_allocated_is_an_error() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let path = dir.join("a.png");
    std::fs::write(&path, "old").unwrap();
    let picture = image::RgbaImage::new(64, 32);
    ALLOCATABLE.with(|a| a.set(Some(1000)));
    let refused = save_png(&path, &picture);
    ALLOCATABLE.with(|a| a.set(None));
    let message = refused.unwrap_err().to_string();
    assert!(message.contains("a.png"), "{message}");
    assert!(
        message.contains("encoding its 64×32 picture takes up to 1 MiB"),
        "{message}"
    );
    assert_eq!(std::fs::read(&path).unwrap(), b"old");
    assert_eq!(
        std::fs::read_dir(dir).unwrap().count(),
        1,
        "a temporary file is left"
    );
    save_png(&path, &picture).unwrap();
    assert_eq!(image::open(&path).unwrap().width(), 64);
}

/// Deferred commits put every file in place together, or, dropped before, none.
#[test]
fn deferred_commits_replace_all_files_or_none() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let (a, b) = (dir.join("a.json"), dir.join("b.json"));
    std::fs::write(&a, "old").unwrap();
    let files = || {
        let mut names: Vec<_> = (std::fs::read_dir(dir).unwrap())
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        names
    };
    for commit in [false, true] {
        let deferred = defer_commits();
        write_bytes(&a, b"new a").unwrap();
        write_bytes(&b, b"new b").unwrap();
        // Written and synced, not yet in place.
        assert_eq!(std::fs::read(&a).unwrap(), b"old");
        assert!(!b.exists());
        assert_eq!(files().len(), 3, "{:?}", files());
        if commit {
            deferred.commit().unwrap();
        } else {
            drop(deferred);
            assert_eq!(files(), ["a.json"], "stopped: as it was");
            assert_eq!(std::fs::read(&a).unwrap(), b"old");
        }
    }
    assert_eq!(files(), ["a.json", "b.json"]);
    assert_eq!(std::fs::read(&a).unwrap(), b"new a");
    // Not deferred any more: a commit puts its file in place at once.
    write_bytes(&b, b"newer b").unwrap();
    assert_eq!(std::fs::read(&b).unwrap(), b"newer b");
}

/// A name of up to 255 bytes, which the file system takes, is written: its temporary
/// file's name, 13 or more bytes longer, was refused ("File name too long").
#[test]
fn the_longest_name_the_file_system_takes_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for length in [240, NAME_MAX] {
        let path = dir.join(format!("{}.json", "a".repeat(length - 5)));
        std::fs::write(&path, "old").unwrap();
        write_bytes(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new", "{length}");
        std::fs::remove_file(&path).unwrap();
        assert_eq!(
            std::fs::read_dir(dir).unwrap().count(),
            0,
            "{length}: a temporary file is left"
        );
    }
}

#[test]
fn an_uncommitted_file_leaves_the_old_one_and_no_temporary_file() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let path = dir.join("a.png");
    std::fs::write(&path, "old").unwrap();
    let mut file = OutputFile::create(&path).unwrap();
    file.write_all(b"half").unwrap();
    drop(file);
    assert_eq!(std::fs::read(&path).unwrap(), b"old");
    assert_eq!(std::fs::read_dir(dir).unwrap().count(), 1);
}

#[test]
fn a_symbolic_link_keeps_pointing_at_the_file_it_named() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("real.json"), "old").unwrap();
    std::os::unix::fs::symlink("real.json", dir.join("link.json")).unwrap();
    write_bytes(&dir.join("link.json"), b"new").unwrap();
    assert!(std::fs::symlink_metadata(dir.join("link.json"))
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read(dir.join("real.json")).unwrap(), b"new");
    assert_eq!(
        identity(&dir.join("link.json")),
        identity(&dir.join("real.json"))
    );
}

#[test]
fn a_full_device_is_an_error_naming_it() {
    let e = write_bytes(Path::new("/dev/full"), b"{}").unwrap_err();
    assert_eq!(e.path, Path::new("/dev/full"));
    assert_eq!(e.source.raw_os_error(), Some(28), "{e}");
    // A caller that ignores a write error (the GIF encoder's trailer) still gets one.
    let mut file = OutputFile::create(Path::new("/dev/full")).unwrap();
    let _ = file.write_all(&[0; 64 * 1024]);
    let _ = file.write_all(b"more");
    let e = file.commit().unwrap_err();
    assert!(e.to_string().contains("/dev/full"), "{e}");
}

#[test]
fn a_dangling_link_writes_its_target() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::os::unix::fs::symlink("new.json", dir.join("link.json")).unwrap();
    assert_eq!(
        identity(&dir.join("link.json")),
        identity(&dir.join("new.json"))
    );
    write_bytes(&dir.join("link.json"), b"new").unwrap();
    assert_eq!(std::fs::read(dir.join("new.json")).unwrap(), b"new");
    assert!(std::fs::symlink_metadata(dir.join("link.json"))
        .unwrap()
        .file_type()
        .is_symlink());
}

#[test]
fn spellings_of_one_file_have_one_identity() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let a = identity(&dir.join("x.png"));
    let b = identity(&dir.join(".").join("x.png"));
    let sub = dir.join("sub");
    std::fs::create_dir(&sub).unwrap();
    let c = identity(&sub.join("..").join("x.png"));
    assert_eq!(a, b);
    assert_eq!(a, c);
    assert_ne!(a, identity(&dir.join("y.png")));
}

/// As the module says: a replaced file is a new one, so another hard link to the old file
/// keeps the old contents.
#[test]
fn a_hard_link_to_a_replaced_file_keeps_the_old_contents() {
    let tmp = tempfile::tempdir().unwrap();
    let (path, link) = (tmp.path().join("a.json"), tmp.path().join("b.json"));
    std::fs::write(&path, "old").unwrap();
    std::fs::hard_link(&path, &link).unwrap();
    write_bytes(&path, b"new").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"new");
    assert_eq!(std::fs::read(&link).unwrap(), b"old");
}
