#!/usr/bin/env bash
# Builds the release archive of velvet for one target, the same way on a laptop and in
# .github/workflows/release.yml (docs/releasing.md):
#
#   scripts/package.sh TARGET [--binary PATH] [--out DIR]
#
# makes DIR/velvet-VERSION-TARGET.tar.gz (.zip for Windows targets), one top folder
# velvet-VERSION-TARGET/ with the binary, README.md, LICENSE-MIT and LICENSE-APACHE, and beside
# it the archive's SHA-256 in sha256sum's format (ARCHIVE.sha256). Without --binary it builds
# the binary with `cargo build --locked --release --target TARGET`; VELVET_CARGO replaces
# `cargo build` (e.g. `cargo zigbuild` or `cross build` for the static musl builds).
set -euo pipefail

prog="package.sh"
usage="usage: scripts/package.sh TARGET [--binary PATH] [--out DIR]"

die() {
    echo "$prog: $*" >&2
    exit 1
}

usage_error() {
    echo "$prog: $*" >&2
    echo "$usage" >&2
    exit 2
}

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

target=""
binary=""
out=""
while [ $# -gt 0 ]; do
    case "$1" in
        --binary | --out)
            [ $# -ge 2 ] || usage_error "$1 needs a value"
            if [ "$1" = --binary ]; then binary="$2"; else out="$2"; fi
            shift 2
            ;;
        --binary=*) binary="${1#--binary=}"; shift ;;
        --out=*) out="${1#--out=}"; shift ;;
        -h | --help) echo "$usage"; exit 0 ;;
        -*) usage_error "unknown option: $1" ;;
        *)
            [ -z "$target" ] || usage_error "one target only, got '$target' and '$1'"
            target="$1"
            shift
            ;;
    esac
done
[ -n "$target" ] || usage_error "no target given"
[ -n "$out" ] || out="$root/dist"

# The version every archive name and binstall's pkg-url carry: [package] version in Cargo.toml.
version="$(sed -n '/^\[package\]/,/^\[/s/^version *= *"\([^"]*\)".*/\1/p' "$root/Cargo.toml" | head -n 1)"
[ -n "$version" ] || die "no [package] version in $root/Cargo.toml"

case "$target" in
    *-windows-*) exe=".exe" ext="zip" ;;
    *) exe="" ext="tar.gz" ;;
esac

if [ -z "$binary" ]; then
    # Word-split on purpose: VELVET_CARGO is a command with its subcommand, `cargo zigbuild`.
    read -r -a build <<<"${VELVET_CARGO:-cargo build}"
    # Standard output is kept for the two paths this prints at the end.
    (cd "$root" && "${build[@]}" --locked --release --target "$target") >&2
    # Cargo ran in the repository, so a relative CARGO_TARGET_DIR is relative to it.
    target_dir="${CARGO_TARGET_DIR:-target}"
    case "$target_dir" in
        /*) ;;
        *) target_dir="$root/$target_dir" ;;
    esac
    binary="$target_dir/$target/release/velvet$exe"
fi
[ -f "$binary" ] || die "no binary at $binary"

name="velvet-$version-$target"
archive="$name.$ext"

mkdir -p "$out"
out="$(cd "$out" && pwd)"

# Everything is made in a hidden folder inside DIR and renamed into place, so that DIR never
# holds a partial archive (the rename stays on one file system) and a failure leaves nothing.
stage=""
cleanup() {
    if [ -n "$stage" ]; then rm -rf "$stage"; fi
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
stage="$(mktemp -d "$out/.package.XXXXXX")"

mkdir "$stage/$name"
cp "$binary" "$stage/$name/velvet$exe"
cp "$root/README.md" "$root/LICENSE-MIT" "$root/LICENSE-APACHE" "$stage/$name/"
chmod 755 "$stage/$name" "$stage/$name/velvet$exe"
chmod 644 "$stage/$name/README.md" "$stage/$name/LICENSE-MIT" "$stage/$name/LICENSE-APACHE"

# The same commit gives the same archive where that is cheap: entries sorted, owners and the
# gzip header's name and time left out, and with GNU tar every file dated by the commit
# (SOURCE_DATE_EPOCH, as reproducible builds name it, first). gzip's default level: -9 made the
# archive under 1% smaller and took three times as long.
epoch="${SOURCE_DATE_EPOCH:-$(git -C "$root" log -1 --format=%ct 2>/dev/null || true)}"

if [ "$ext" = zip ]; then
    if command -v zip >/dev/null 2>&1; then
        (cd "$stage" && find "$name" | LC_ALL=C sort | zip -X -q "$archive" -@)
    elif command -v 7z >/dev/null 2>&1; then
        # Git Bash on the Windows runners has no zip; 7-Zip is installed there.
        (cd "$stage" && 7z a -tzip -bd "$archive" "$name" >/dev/null)
    else
        die "neither zip nor 7z found to make $archive"
    fi
else
    if tar --version 2>/dev/null | grep -q 'GNU tar'; then
        gnu=(--sort=name --owner=0 --group=0 --numeric-owner --format=gnu)
        if [ -n "$epoch" ]; then gnu+=(--mtime="@$epoch"); fi
        (cd "$stage" && tar "${gnu[@]}" -cf - "$name" | gzip -n >"$archive")
    else
        # macOS's tar would add a `._` entry for each file with extended attributes.
        (cd "$stage" && COPYFILE_DISABLE=1 tar -cf - "$name" | gzip -n >"$archive")
    fi
fi

# Only the hash is read from the tool, so the line is `HASH  NAME` whichever tool made it and
# however that tool marks a binary file.
if command -v sha256sum >/dev/null 2>&1; then
    hash="$(sha256sum <"$stage/$archive")"
elif command -v shasum >/dev/null 2>&1; then
    hash="$(shasum -a 256 <"$stage/$archive")"
else
    die "neither sha256sum nor shasum found to hash $archive"
fi
hash="${hash%% *}"
printf '%s  %s\n' "$hash" "$archive" >"$stage/$archive.sha256"

# The old checksum goes first and the new one comes last: an interruption leaves an archive
# without a checksum, never a checksum that does not match its archive.
rm -f "$out/$archive.sha256"
mv -f "$stage/$archive" "$out/$archive"
mv -f "$stage/$archive.sha256" "$out/$archive.sha256"

echo "$out/$archive"
echo "$out/$archive.sha256"
