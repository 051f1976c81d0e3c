//! The index pages of a preview run: static HTML (no scripts, no external resources), the
//! sheets worst first by the plan's verdict, [`PAGE`] to a page with links between the pages;
//! a page's sheets can be shown by verdict and in input order instead, through radio buttons
//! and style rules alone (a section's class is its label, its `--input` its input order).
//! Each sheet is shown with its title, the materials that share it, the report's figures and
//! the verdict as text; the first page also lists the sheets left undrawn (`--worst N`), the
//! files without sheen or fuzz and the files that failed. [`json`] writes the same run as
//! `index.json` for tools, which a rerun reads ([`listed_sheets`]) to remove the sheets it no
//! longer writes.

use super::{Drawn, Plan};

/// Sheets on one page.
pub const PAGE: usize = 100;

/// The file name of page `page` (0-based): index.html, index-2.html, ….
pub fn page_name(page: usize) -> String {
    if page == 0 {
        "index.html".to_string()
    } else {
        format!("index-{}.html", page + 1)
    }
}

/// `text` with the five HTML special characters escaped.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// The index pages of `plan` with the sheets `drawn` (worst first): at least one page, each
/// with [`PAGE`] sheets at most.
pub fn pages(plan: &Plan, drawn: &[Drawn]) -> Vec<String> {
    let chunks: Vec<&[Drawn]> = if drawn.is_empty() {
        vec![&[]]
    } else {
        drawn.chunks(PAGE).collect()
    };
    let total = chunks.len();
    chunks
        .iter()
        .enumerate()
        .map(|(page, sheets)| html(plan, sheets, page, total, drawn.len()))
        .collect()
}

fn nav(page: usize, total: usize) -> String {
    if total == 1 {
        return String::new();
    }
    let mut h = String::from("<p class=\"nav\">pages:");
    for p in 0..total {
        if p == page {
            h += &format!(" <b>{}</b>", p + 1);
        } else {
            h += &format!(" <a href=\"{}\">{}</a>", page_name(p), p + 1);
        }
    }
    h + "</p>\n"
}

fn html(plan: &Plan, sheets: &[Drawn], page: usize, total: usize, drawn: usize) -> String {
    let mut h = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>velvet preview</title>\n<style>\n\
         body { font-family: sans-serif; background: #111; color: #ddd; margin: 2em; }\n\
         section { margin-bottom: 3em; }\n img { max-width: 100%; }\n\
         .verdict { font-weight: bold; }\n a { color: #9cf; }\n\
         .sheets { display: flex; flex-direction: column; }\n\
         #show-visible:checked ~ .sheets section:not(.visible),\n\
         #show-close:checked ~ .sheets section:not(.close),\n\
         #show-same:checked ~ .sheets section:not(.same) { display: none; }\n\
         #order-input:checked ~ .sheets section { order: var(--input); }\n\
         body > input { display: none; }\n label { cursor: pointer; text-decoration: underline; }\n\
         #show-all:checked ~ p label[for=show-all], #show-visible:checked ~ p label[for=show-visible],\n\
         #show-close:checked ~ p label[for=show-close], #show-same:checked ~ p label[for=show-same],\n\
         #order-verdict:checked ~ p label[for=order-verdict],\n\
         #order-input:checked ~ p label[for=order-input] { font-weight: bold; text-decoration: none; }\n\
         </style>\n</head>\n<body>\n<h1>velvet preview</h1>\n",
    );
    h += &format!(
        "<p>{} material(s) on {} sheet(s) (materials with the same values share one), {drawn} \
         drawn, worst first by the plan's verdict: the &#42791;LIP difference between the \
         material as authored and as written, in the furnace (which gives the label) and under \
         the light, as `velvet migrate` reports it. Each sheet \
         shows the material as authored, as migrated and as a loader without \
         KHR_materials_fuzz sees it, in a white furnace (top row of each pair) and under one \
         directional light with a dim ambient; the last column is the difference between the \
         first two, amplified {}&times;.</p>\n",
        plan.entries.len(),
        plan.sheets.len(),
        super::sheet::DIFF_GAIN
    );
    if page == 0 && drawn > 0 {
        h += "<p><a href=\"overview.png\"><img src=\"overview.png\" alt=\"histogram of the verdicts and the worst sheets\"></a></p>\n";
    }
    // Show by verdict, and in input order, with no script: radio buttons before the sheets,
    // which the style rules read.
    let count = |label: crate::migrate::verdict::Label| {
        sheets
            .iter()
            .filter(|d| plan.sheets[d.sheet].verdict.label == label)
            .count()
    };
    use crate::migrate::verdict::Label;
    let shows = ["all", "visible", "close", "same"];
    for (i, show) in shows.iter().enumerate() {
        let checked = if i == 0 { " checked" } else { "" };
        h += &format!("<input type=\"radio\" name=\"show\" id=\"show-{show}\"{checked}>\n");
    }
    h += "<input type=\"radio\" name=\"order\" id=\"order-verdict\" checked>\n\
          <input type=\"radio\" name=\"order\" id=\"order-input\">\n";
    h += "<p>show: <label for=\"show-all\">all</label>";
    for label in [Label::Visible, Label::Close, Label::Same] {
        h += &format!(
            " &middot; <label for=\"show-{0}\">{0} ({1})</label>",
            label.as_str(),
            count(label)
        );
    }
    h += "<br>order: <label for=\"order-verdict\">worst first</label> &middot; \
          <label for=\"order-input\">input order</label></p>\n";
    h += &nav(page, total);
    h += "<div class=\"sheets\">\n";
    for d in sheets {
        let planned = &plan.sheets[d.sheet];
        let sum = &d.summary;
        let name = d
            .path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        h += &format!(
            "<section class=\"{}\" style=\"--input: {}\">\n",
            planned.verdict.label.as_str(),
            planned.entries.first().copied().unwrap_or(0)
        );
        h += &format!("<h2>{}. {}</h2>\n", d.sheet + 1, escape(&sum.title));
        h += &format!(
            "<p>{} (the plan's verdict: {})</p>\n",
            escape(sum.kind),
            planned.verdict.describe()
        );
        h += &format!(
            "<a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"></a>\n",
            escape(&name),
            escape(&sum.title)
        );
        if planned.entries.len() > 1 {
            h += "<details><summary>materials on this sheet</summary><ul>\n";
            for &e in &planned.entries {
                h += &format!("<li>{}</li>\n", escape(&plan.entries[e].title()));
            }
            h += "</ul></details>\n";
        }
        h += "<ul>\n";
        for f in &sum.figures {
            h += &format!("<li>{}</li>\n", escape(f));
        }
        h += "</ul>\n";
        h += &format!("<p class=\"verdict\">{}</p>\n", escape(&sum.verdict_line()));
        for n in &sum.notes {
            h += &format!("<p>note: {}</p>\n", escape(n));
        }
        h += "</section>\n";
    }
    h += "</div>\n";
    h += &nav(page, total);
    if page == 0 {
        if drawn < plan.sheets.len() {
            h += &format!(
                "<h2>Sheets not drawn</h2>\n<p>{} sheet(s) rank below those drawn (run without \
                 --worst to draw them):</p>\n<ul>\n",
                plan.sheets.len() - drawn
            );
            for s in &plan.sheets[drawn..] {
                h += &format!("<li>{} ({})</li>\n", escape(&s.title), s.verdict.describe());
            }
            h += "</ul>\n";
        }
        if !plan.without_layers.is_empty() {
            h += "<h2>Files without a sheen or fuzz layer</h2>\n<ul>\n";
            for f in &plan.without_layers {
                h += &format!("<li>{}</li>\n", escape(&f.display().to_string()));
            }
            h += "</ul>\n";
        }
        if !plan.failures.is_empty() {
            h += "<h2>Files that could not be previewed</h2>\n<ul>\n";
            for f in &plan.failures {
                h += &format!(
                    "<li>{}: {}</li>\n",
                    escape(&f.file.display().to_string()),
                    escape(&f.message)
                );
            }
            h += "</ul>\n";
        }
    }
    h += "</body>\n</html>\n";
    h
}

/// The machine-readable index of a run, `index.json`: one record per material, in the order
/// of the pages (worst first by the plan's verdict, then the materials a sheet shows in input
/// order), each with its sheet's file name (`file`, in the output folder), the asset
/// (`asset`, as titles name it), the material's index and name, the plan's verdict (`label`,
/// `flip`, `furnace`, `light`), whether its sheet was drawn in this run (`drawn`: `--worst`
/// leaves sheets undrawn, a stop leaves the rest) and the layers as written at the factors
/// (`written`: `sheen` `{color, roughness}` and `fuzz` `{weight, color, roughness}`, each
/// present when the written file holds that layer).
pub fn json(plan: &Plan, drawn: &[Drawn]) -> String {
    use serde_json::{json, Map, Value};
    let drawn_sheets: std::collections::HashSet<usize> = drawn.iter().map(|d| d.sheet).collect();
    let mut records = Vec::new();
    for (s, sheet) in plan.sheets.iter().enumerate() {
        let factors = &sheet.material.factors;
        let mut written = Map::new();
        if let Some(sheen) = factors.written_sheen {
            written.insert(
                "sheen".into(),
                json!({"color": sheen.color, "roughness": sheen.roughness}),
            );
        }
        if let Some(fuzz) = factors.written_fuzz {
            written.insert(
                "fuzz".into(),
                json!({"weight": fuzz.weight, "color": fuzz.color, "roughness": fuzz.roughness}),
            );
        }
        for &e in &sheet.entries {
            let entry = &plan.entries[e];
            records.push(json!({
                "file": sheet.name,
                "asset": entry.label,
                "material": entry.index,
                "name": entry.name,
                "label": sheet.verdict.label.as_str(),
                "flip": sheet.verdict.flip,
                "furnace": sheet.verdict.furnace,
                "light": sheet.verdict.light,
                "drawn": drawn_sheets.contains(&s),
                "written": Value::Object(written.clone()),
            }));
        }
    }
    let mut out =
        serde_json::to_string_pretty(&json!({ "sheets": records })).expect("an index serialises");
    out.push('\n');
    out
}

/// The sheet files an earlier run's `index.json` lists as drawn: plain names of PNG files in
/// the output folder (anything else, or a file that does not read as an index, lists none, so
/// that a rerun never removes a file it did not write).
pub fn listed_sheets(index_json: &str) -> Vec<String> {
    let Ok(value) = serde_json::from_str::<serde_json::Value>(index_json) else {
        return Vec::new();
    };
    let mut names: Vec<String> = value
        .get("sheets")
        .and_then(serde_json::Value::as_array)
        .into_iter()
        .flatten()
        .filter(|r| r.get("drawn").and_then(serde_json::Value::as_bool) == Some(true))
        .filter_map(|r| r.get("file").and_then(serde_json::Value::as_str))
        .filter(|name| {
            name.ends_with(".png")
                && !name.contains(['/', '\\'])
                && !name.starts_with('.')
                && *name != "overview.png"
        })
        .map(str::to_owned)
        .collect();
    names.sort();
    names.dedup();
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup() {
        assert_eq!(
            escape("<a href='x'>&\"</a>"),
            "&lt;a href=&#39;x&#39;&gt;&amp;&quot;&lt;/a&gt;"
        );
    }

    #[test]
    fn an_empty_run_is_one_valid_page_that_says_so() {
        let pages = pages(&Plan::default(), &[]);
        assert_eq!(pages.len(), 1);
        assert!(pages[0].starts_with("<!DOCTYPE html>") && pages[0].ends_with("</html>\n"));
        assert!(pages[0].contains("<p>0 material(s) on 0 sheet(s)"));
    }

    #[test]
    fn pages_are_named_index_then_numbered_from_two() {
        assert_eq!(
            [0, 1, 9].map(page_name),
            ["index.html", "index-2.html", "index-10.html"]
        );
    }
}
