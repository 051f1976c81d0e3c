//! scripts/package.sh, which makes the release archives (docs/releasing.md), run on the binary
//! this test build made, for the host target: what the archive holds, that its binary is the
//! input byte for byte, that the checksum file is right, and that a failure leaves nothing.

use std::fs::{self, File};
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn package(args: &[&str]) -> Output {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/package.sh");
    Command::new("bash")
        .arg(script)
        .args(args)
        .output()
        .expect("bash runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8(bytes.to_vec()).expect("UTF-8 output")
}

/// The target rustc builds for by default: the `host:` line of `rustc -vV`.
fn host_target() -> String {
    let o = Command::new("rustc")
        .arg("-vV")
        .output()
        .expect("rustc runs");
    text(&o.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .expect("rustc -vV names the host")
        .to_string()
}

fn has_tar() -> bool {
    Command::new("tar").arg("--version").output().is_ok()
}

/// The file names in `dir`, sorted.
fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    names
}

/// Whether two files hold the same bytes, read in blocks: the debug binary is hundreds of MB.
fn same_bytes(a: &Path, b: &Path) -> bool {
    if fs::metadata(a).unwrap().len() != fs::metadata(b).unwrap().len() {
        return false;
    }
    let mut a = BufReader::new(File::open(a).unwrap());
    let mut b = BufReader::new(File::open(b).unwrap());
    let (mut block_a, mut block_b) = (vec![0u8; 1 << 16], vec![0u8; 1 << 16]);
    loop {
        let n = a.read(&mut block_a).unwrap();
        if n == 0 {
            return true;
        }
        b.read_exact(&mut block_b[..n]).unwrap();
        if block_a[..n] != block_b[..n] {
            return false;
        }
    }
}

/// The SHA-256 of `file` in hex, from whichever of sha256sum and shasum is installed.
fn sha256_hex(file: &Path) -> String {
    let o = Command::new("sha256sum")
        .arg(file)
        .output()
        .or_else(|_| {
            Command::new("shasum")
                .args(["-a", "256"])
                .arg(file)
                .output()
        })
        .expect("sha256sum or shasum runs");
    assert!(o.status.success(), "{}", text(&o.stderr));
    text(&o.stdout)
        .split_whitespace()
        .next()
        .unwrap()
        .to_string()
}

#[test]
fn archive_holds_one_folder_with_the_binary_readme_and_licences_and_a_matching_checksum() {
    if !has_tar() {
        eprintln!("skipped: no `tar` to list the archive with");
        return;
    }
    let target = host_target();
    let binary = Path::new(env!("CARGO_BIN_EXE_velvet"));
    let out = tempfile::tempdir().unwrap();
    let o = package(&[
        &target,
        "--binary",
        binary.to_str().unwrap(),
        "--out",
        out.path().to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));

    let folder = format!("velvet-{}-{target}", env!("CARGO_PKG_VERSION"));
    let name = format!("{folder}.tar.gz");
    let archive = out.path().join(&name);
    let checksum = out.path().join(format!("{name}.sha256"));
    assert_eq!(
        text(&o.stdout),
        format!("{}\n{}\n", archive.display(), checksum.display())
    );
    // No staging folder or partial file is left beside the two.
    assert_eq!(
        names_in(out.path()),
        [name.clone(), format!("{name}.sha256")]
    );

    let listing = Command::new("tar")
        .arg("-tzf")
        .arg(&archive)
        .output()
        .unwrap();
    assert!(listing.status.success(), "{}", text(&listing.stderr));
    let mut entries: Vec<String> = text(&listing.stdout).lines().map(String::from).collect();
    entries.sort();
    let expected: Vec<String> = ["", "LICENSE-APACHE", "LICENSE-MIT", "README.md", "velvet"]
        .iter()
        .map(|f| format!("{folder}/{f}"))
        .collect();
    assert_eq!(entries, expected);

    let unpacked = tempfile::tempdir().unwrap();
    let x = Command::new("tar")
        .arg("-xzf")
        .arg(&archive)
        .arg("-C")
        .arg(unpacked.path())
        .output()
        .unwrap();
    assert!(x.status.success(), "{}", text(&x.stderr));
    let inside = unpacked.path().join(&folder);
    assert!(same_bytes(&inside.join("velvet"), binary));
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = fs::metadata(inside.join("velvet"))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode & 0o777, 0o755);
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    for file in ["README.md", "LICENSE-MIT", "LICENSE-APACHE"] {
        assert!(same_bytes(&inside.join(file), &root.join(file)), "{file}");
    }

    assert_eq!(
        fs::read_to_string(&checksum).unwrap(),
        format!("{}  {name}\n", sha256_hex(&archive))
    );
}

#[test]
fn a_missing_binary_exits_1_naming_the_path_and_leaves_the_out_dir_empty() {
    let elsewhere = tempfile::tempdir().unwrap();
    let missing = elsewhere.path().join("no-such-velvet");
    let out = tempfile::tempdir().unwrap();
    let o = package(&[
        &host_target(),
        "--binary",
        missing.to_str().unwrap(),
        "--out",
        out.path().to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        text(&o.stderr),
        format!("package.sh: no binary at {}\n", missing.display())
    );
    assert_eq!(text(&o.stdout), "");
    assert!(names_in(out.path()).is_empty());
}

#[test]
fn an_unknown_option_exits_2_with_the_usage_and_builds_nothing() {
    let out = tempfile::tempdir().unwrap();
    let o = package(&[
        "x86_64-unknown-linux-gnu",
        "--strip",
        "--out",
        out.path().to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        text(&o.stderr),
        "package.sh: unknown option: --strip\n\
         usage: scripts/package.sh TARGET [--binary PATH] [--out DIR]\n"
    );
    assert!(names_in(out.path()).is_empty());
}
