//! Errors that point into the user's file: `file:line:col`, a caret snippet, what was expected,
//! and a "did you mean" hint.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// An error located in a source file.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    /// The file the error is in.
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// What is wrong and what was expected.
    pub message: String,
    /// The offending source line.
    pub source_line: String,
    /// Width of the caret underline, in characters (at least 1).
    pub caret_width: usize,
    /// A suggestion, such as "did you mean `radius`?".
    pub help: Option<String>,
}

impl Diagnostic {
    /// Locates byte range `span` of `src`.
    pub fn at(file: &Path, src: &str, span: Range<usize>, message: impl Into<String>) -> Self {
        let mut start = span.start.min(src.len());
        while !src.is_char_boundary(start) {
            start -= 1;
        }
        let mut span_end = span.end.max(start).min(src.len());
        while !src.is_char_boundary(span_end) {
            span_end += 1;
        }
        let line_start = src[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = src[start..].find('\n').map_or(src.len(), |i| start + i);
        let source_line = src[line_start..line_end].trim_end_matches('\r').to_string();
        let end = span_end.clamp(start, line_end);
        Self {
            file: file.to_path_buf(),
            line: src[..start].matches('\n').count() + 1,
            column: src[line_start..start].chars().count() + 1,
            message: message.into(),
            source_line,
            caret_width: src[start..end].chars().count().max(1),
            help: None,
        }
    }

    /// Adds a help line.
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }
}

/// The most characters of a source line a snippet shows: a minified file (a glTF's JSON, its
/// buffers inline) is one line of megabytes.
const SNIPPET: usize = 100;
/// Of those, how many come before the error's column when the line is cut.
const BEFORE: usize = 40;

impl Diagnostic {
    /// The source line as the snippet shows it — whole, or cut to [`SNIPPET`] characters about
    /// the column with `…` where it was cut —, the caret's offset in it and the caret's width.
    fn snippet(&self) -> (String, usize, usize) {
        let col = self.column.saturating_sub(1);
        let count = self.source_line.chars().count();
        if count <= SNIPPET {
            return (self.source_line.clone(), col, self.caret_width);
        }
        let col = col.min(count);
        let end = (col.saturating_sub(BEFORE) + SNIPPET).min(count);
        let start = end - SNIPPET;
        let mut shown: String = if start > 0 { "…".into() } else { String::new() };
        shown.extend(self.source_line.chars().skip(start).take(end - start));
        if end < count {
            shown.push('…');
        }
        let caret = col - start + usize::from(start > 0);
        (shown, caret, self.caret_width.min(end.saturating_sub(col)).max(1))
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}:{}:{}: {}", self.file.display(), self.line, self.column, self.message)?;
        let gutter = self.line.to_string().len();
        writeln!(f, "{:gutter$} |", "")?;
        let (shown, caret, width) = self.snippet();
        writeln!(f, "{} | {}", self.line, shown)?;
        let pad: String = shown.chars().take(caret).map(|c| if c == '\t' { '\t' } else { ' ' }).collect();
        write!(f, "{:gutter$} | {pad}{}", "", "^".repeat(width))?;
        if let Some(h) = &self.help {
            write!(f, "\n{:gutter$} = help: {h}", "")?;
        }
        Ok(())
    }
}

/// The closest candidate to `word` when it is close enough to be a likely typo.
pub fn did_you_mean<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .into_iter()
        .map(|c| (strsim::jaro_winkler(word, c), c))
        .filter(|(score, _)| *score > 0.8)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn position_and_caret() {
        let src = "a = 1\nradius = -1.0\n";
        let d = Diagnostic::at(Path::new("s.toml"), src, 15..19, "radius must be positive");
        assert_eq!((d.line, d.column, d.caret_width), (2, 10, 4));
        let text = d.to_string();
        assert!(text.starts_with("s.toml:2:10: radius must be positive"));
        assert!(text.contains("2 | radius = -1.0\n  |          ^^^^"), "{text}");
    }

    /// A line longer than a snippet (a minified JSON file) is shown cut about the column, the
    /// caret under the same character, `file:line:col` the whole line's.
    #[test]
    fn long_lines_are_cut_about_the_column() {
        let src = format!("{}\"radius\": -1{}", "x".repeat(5000), "y".repeat(5000));
        let d = Diagnostic::at(Path::new("s.gltf"), &src, 5000..5008, "bad");
        assert_eq!((d.line, d.column, d.caret_width), (1, 5001, 8));
        let text = d.to_string();
        assert!(text.starts_with("s.gltf:1:5001: bad"), "{text}");
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines.iter().all(|l| l.chars().count() < SNIPPET + 10), "{text}");
        let (shown, caret) = (lines[2], lines[3]);
        let at = caret.chars().position(|c| c == '^').unwrap();
        let under: String = shown.chars().skip(at).take(8).collect();
        assert_eq!(under, "\"radius\"", "{text}");
        assert!(shown.starts_with("1 | …") && shown.ends_with('…'), "{shown}");
        // At the start and at the end of such a line, cut on one side only.
        for (span, first) in [(0..1, 'x'), (src.len() - 1..src.len(), '…')] {
            let text = Diagnostic::at(Path::new("s.gltf"), &src, span, "bad").to_string();
            let shown = text.lines().nth(2).unwrap();
            assert_eq!(shown.chars().nth(4), Some(first), "{shown}");
            let caret = text.lines().nth(3).unwrap();
            let at = caret.chars().position(|c| c == '^').unwrap();
            assert!(at < shown.chars().count(), "{text}");
        }
    }

    #[test]
    fn suggestions() {
        assert_eq!(did_you_mean("radus", ["center", "radius"]), Some("radius"));
        assert_eq!(did_you_mean("zzz", ["center", "radius"]), None);
    }
}
