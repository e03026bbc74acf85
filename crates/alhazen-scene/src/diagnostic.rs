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

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}:{}:{}: {}", self.file.display(), self.line, self.column, self.message)?;
        let gutter = self.line.to_string().len();
        writeln!(f, "{:gutter$} |", "")?;
        writeln!(f, "{} | {}", self.line, self.source_line)?;
        let pad: String =
            self.source_line.chars().take(self.column - 1).map(|c| if c == '\t' { '\t' } else { ' ' }).collect();
        write!(f, "{:gutter$} | {pad}{}", "", "^".repeat(self.caret_width))?;
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

    #[test]
    fn suggestions() {
        assert_eq!(did_you_mean("radus", ["center", "radius"]), Some("radius"));
        assert_eq!(did_you_mean("zzz", ["center", "radius"]), None);
    }
}
