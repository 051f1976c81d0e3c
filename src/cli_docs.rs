//! Documentation generated from the command-line definition: the exit-status text that `--help`
//! shows, and man pages (clap_mangen) in which that text becomes an EXIT STATUS section instead
//! of clap_mangen's generic EXTRA section, as man pages conventionally have it.

use clap_mangen::roff::{bold, roman, Roff};
use clap_mangen::Man;
use std::path::Path;

/// The exit statuses of `velvet validate`, as `--help` prints them: one `  N  meaning` line each.
pub const EXIT_STATUS: &str = "\
Exit status:
  0  no file has an issue at or above --fail-on (with --fix: none is left after fixing)
  1  a file has an issue at or above --fail-on (with --fix: after fixing; a file that cannot be read, parsed or written has an error), or --diff shows a change, or --exit-non-zero-on-fix and --fix changed a file
  2  usage or configuration error (bad flag, unknown code, invalid velvet.toml, a path that does not exist or is not a regular file or folder, a folder without .gltf/.glb files, every file found in the folders given excluded; excluded files named one by one are skipped)";

/// The exit statuses of every command that works on files, for `velvet --help`: what each
/// status means for each command (each command's `--help` gives its own).
pub const EXIT_STATUS_ALL: &str = "\
Exit status:
  0  validate: no file has an issue at or above --fail-on (with --fix: none is left after fixing); migrate, bake: every file done, or nothing to do; preview: every sheet written
  1  validate: a file has an issue at or above --fail-on (a file that cannot be read or parsed has an error), --diff shows a change, or --fix --exit-non-zero-on-fix changed a file; migrate: a file failed (the others are still written) or, with --check, a file would change; bake: a file failed (the others are still written); preview: a file could not be previewed or a sheet not written
  2  usage or configuration error in validate, migrate, bake or preview (bad flag, unknown code, invalid velvet.toml, a path that does not exist or is not a regular file or folder, a folder without .gltf/.glb files, every file found in the folders given excluded, a refused output); migrate, bake and preview then write nothing
  130  migrate, bake: stopped by SIGINT (143: by SIGTERM); the files finished before are complete, nothing is left of the others; preview: the sheets written are complete and listed in index.json";

const HEADING: &str = "Exit status:\n";

/// The EXIT STATUS section in roff, from exit-status text.
fn exit_status_section(text: &str) -> String {
    let mut roff = Roff::new();
    roff.control("SH", ["EXIT STATUS"]);
    for line in text.lines().skip(1) {
        let (status, meaning) = line.trim().split_once("  ").unwrap_or((line.trim(), ""));
        roff.control("TP", [])
            .text([bold(status)])
            .text([roman(meaning.trim())]);
    }
    // The text has no apostrophes, so the page's own apostrophe preamble is not repeated.
    roff.to_roff()
}

/// The man page of `command`, its after-help turned into EXIT STATUS when it is exit-status
/// text.
pub fn man_page(command: clap::Command) -> std::io::Result<Vec<u8>> {
    let exit_status = command
        .get_after_help()
        .map(|h| h.to_string())
        .filter(|h| h.starts_with(HEADING));
    let mut page = Vec::new();
    Man::new(command).render(&mut page)?;
    let Some(exit_status) = exit_status else {
        return Ok(page);
    };
    let text = String::from_utf8(page).expect("clap_mangen writes UTF-8");
    // clap_mangen renders after-help as the EXTRA section; replace that section.
    let Some(start) = text.find(".SH EXTRA\n") else {
        return Ok(text.into_bytes());
    };
    let end = text[start + 1..]
        .find("\n.SH ")
        .map_or(text.len(), |i| start + 1 + i + 1);
    let section = exit_status_section(&exit_status);
    Ok(format!("{}{section}{}", &text[..start], &text[end..]).into_bytes())
}

/// Writes one page per command into `dir`: `velvet.1`, `velvet-validate.1`, …
pub fn write_man_pages(command: clap::Command, dir: &Path) -> std::io::Result<()> {
    fn write(command: clap::Command, dir: &Path) -> std::io::Result<()> {
        for sub in command
            .get_subcommands()
            .filter(|s| !s.is_hide_set())
            .cloned()
        {
            write(sub, dir)?;
        }
        let name = Man::new(command.clone()).get_filename();
        crate::edit::write::write_atomic(&dir.join(name), &man_page(command)?)
    }
    std::fs::create_dir_all(dir)?;
    let mut command = command.disable_help_subcommand(true);
    command.build();
    write(command, dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_status_becomes_a_man_section_with_one_entry_per_status() {
        let command = clap::Command::new("demo")
            .after_help(EXIT_STATUS)
            .subcommand(clap::Command::new("sub"));
        let page = String::from_utf8(man_page(command).unwrap()).unwrap();
        assert!(!page.contains(".SH EXTRA"), "{page}");
        let section = &page[page.find(".SH \"EXIT STATUS\"").expect("section present")..];
        assert!(section.starts_with(".SH \"EXIT STATUS\"\n.TP\n\\fB0\\fR\nno file has an issue at or above \\-\\-fail\\-on (with \\-\\-fix: none is left after fixing)\n.TP\n\\fB1\\fR\n"), "{section}");
        assert_eq!(section.matches(".TP").count(), 3);
    }

    #[test]
    fn pages_without_the_exit_status_text_are_left_as_clap_mangen_renders_them() {
        let command = clap::Command::new("demo").after_help("Other notes.");
        let page = String::from_utf8(man_page(command).unwrap()).unwrap();
        assert!(page.contains(".SH EXTRA\nOther notes."), "{page}");
    }
}
