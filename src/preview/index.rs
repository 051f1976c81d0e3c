//! The index page of a preview run: one static HTML file (no scripts, no external resources)
//! that shows every sheet with its title, the report's figures and the verdict as text, and
//! lists the files without sheen or fuzz and the files that failed.

use super::Previews;

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

/// The index page for `previews`.
pub fn html(previews: &Previews) -> String {
    let mut h = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>velvet preview</title>\n<style>\n\
         body { font-family: sans-serif; background: #111; color: #ddd; margin: 2em; }\n\
         section { margin-bottom: 3em; }\n img { max-width: 100%; image-rendering: pixelated; }\n\
         .verdict { font-weight: bold; }\n a { color: #9cf; }\n</style>\n</head>\n<body>\n\
         <h1>velvet preview</h1>\n",
    );
    h += &format!(
        "<p>{} sheet(s). Each shows the material as authored, as migrated and as a loader \
         without KHR_materials_fuzz sees it, in a white furnace (top row of each pair) and \
         under one directional light with a dim ambient; the last column is the difference \
         between the first two, amplified {}&times;.</p>\n",
        previews.sheets.len(),
        super::sheet::DIFF_GAIN
    );
    for s in &previews.sheets {
        let sum = &s.summary;
        h += "<section>\n";
        h += &format!("<h2>{}</h2>\n", escape(&sum.title));
        h += &format!("<p>{}</p>\n", escape(sum.kind));
        h += &format!(
            "<a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"></a>\n",
            escape(&s.name),
            escape(&sum.title)
        );
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
    if !previews.without_layers.is_empty() {
        h += "<h2>Files without a sheen or fuzz layer</h2>\n<ul>\n";
        for f in &previews.without_layers {
            h += &format!("<li>{}</li>\n", escape(&f.display().to_string()));
        }
        h += "</ul>\n";
    }
    if !previews.failures.is_empty() {
        h += "<h2>Files that could not be previewed</h2>\n<ul>\n";
        for f in &previews.failures {
            h += &format!(
                "<li>{}: {}</li>\n",
                escape(&f.file.display().to_string()),
                escape(&f.message)
            );
        }
        h += "</ul>\n";
    }
    h += "</body>\n</html>\n";
    h
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
    fn an_empty_run_is_a_valid_page_that_says_so() {
        let page = html(&Previews::default());
        assert!(page.starts_with("<!DOCTYPE html>") && page.ends_with("</html>\n"));
        assert!(page.contains("<p>0 sheet(s)."));
    }
}
