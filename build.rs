//! Names the build in `velvet --version`: built from a git checkout, the version is followed by
//! the commit's short hash, and by "modified" when tracked files differ from it
//! (`velvet 0.1.0 (abc1234, modified)`); built from a source without `.git` (a crates.io
//! package), or where `git` is missing or fails, it is the package version alone. The result
//! is `VELVET_VERSION` for `main.rs`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    let version = env!("CARGO_PKG_VERSION");
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    // Only velvet's own checkout names the build: a package unpacked inside some other
    // repository (a vendored copy) must not carry that repository's commit. `.git` is a folder
    // in a clone and a file in a worktree.
    let described = if manifest.join(".git").exists() {
        describe(&manifest)
    } else {
        None
    };
    match described {
        Some(build) => println!("cargo:rustc-env=VELVET_VERSION={version} ({build})"),
        None => println!("cargo:rustc-env=VELVET_VERSION={version}"),
    }
}

/// "abc1234" or "abc1234, modified", with the files whose change makes cargo run this again;
/// None when git cannot say.
fn describe(dir: &Path) -> Option<String> {
    let hash = git(dir, &["rev-parse", "--short", "HEAD"])?;
    // A commit, a checkout or a branch moving on changes HEAD or the ref it names (loose, or
    // packed once `git gc` ran); staging changes the index. With any rerun-if-changed given,
    // cargo no longer reruns this for a changed source file on its own, so the sources are
    // named too: an edit there is what makes the build "modified".
    let mut watched = vec![git(dir, &["rev-parse", "--git-path", "HEAD"])?];
    if let Some(branch) = git(dir, &["symbolic-ref", "-q", "HEAD"]) {
        watched.push(git(dir, &["rev-parse", "--git-path", &branch])?);
        watched.push(git(dir, &["rev-parse", "--git-path", "packed-refs"])?);
    }
    watched.push(git(dir, &["rev-parse", "--git-path", "index"])?);
    for path in watched {
        // --git-path answers relative to the folder git ran in.
        println!("cargo:rerun-if-changed={}", dir.join(path).display());
    }
    for source in ["src", "schema", "build.rs", "Cargo.toml", "Cargo.lock"] {
        println!("cargo:rerun-if-changed={}", dir.join(source).display());
    }
    // Tracked files only: a stray untracked file does not change what is built.
    let status = git(dir, &["status", "--porcelain", "--untracked-files=no"])?;
    Some(if status.is_empty() {
        hash
    } else {
        format!("{hash}, modified")
    })
}

/// The trimmed standard output of `git ARGS` run in `dir`, or None when git is missing, fails
/// or prints something that is not UTF-8.
fn git(dir: &Path, args: &[&str]) -> Option<String> {
    // --no-optional-locks: `git status` would otherwise refresh the index file, newer then than
    // this run, and cargo would run this again on every build.
    let output = Command::new("git")
        .arg("--no-optional-locks")
        .arg("-C")
        .arg(dir)
        .args(args)
        .output()
        .ok()?;
    if !output.status.success() {
        return None;
    }
    String::from_utf8(output.stdout)
        .ok()
        .map(|s| s.trim().to_string())
}
