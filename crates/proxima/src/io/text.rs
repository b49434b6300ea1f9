//! Whitespace-separated tokens of a text file, with 1-based line numbers.

use std::str::{Lines, SplitAsciiWhitespace};

/// A token stream over text that knows the line of the last token returned.
pub(crate) struct Tokens<'a> {
    lines: std::iter::Enumerate<Lines<'a>>,
    base: usize,
    current: SplitAsciiWhitespace<'a>,
    /// Line of the most recent token (the last line once exhausted).
    pub line: usize,
}

impl<'a> Tokens<'a> {
    /// Tokens of `text`, whose first line is line `first_line` of the file.
    pub fn new(text: &'a str, first_line: usize) -> Tokens<'a> {
        Tokens {
            lines: text.lines().enumerate(),
            base: first_line,
            current: "".split_ascii_whitespace(),
            line: first_line,
        }
    }

    /// The next token, or `None` at the end of the text.
    pub fn next_token(&mut self) -> Option<&'a str> {
        loop {
            if let Some(t) = self.current.next() {
                return Some(t);
            }
            let (i, l) = self.lines.next()?;
            self.line = self.base + i;
            self.current = l.split_ascii_whitespace();
        }
    }
}
