//! The pieces every line-oriented text format of Proxima is read with: the
//! scene trace of `proxima replay` ([`crate::trace`]) and the world trace of
//! `proxima world` (issue #13), which reads its lines with the same helpers.
//!
//! A line is the text before the first `#`, split at ASCII white space
//! ([`Line::split`]); every field error names the field, and a whole-file error
//! is a [`ParseError`] printed as `line N: message`.

use proxima::geom::Sphere;
use proxima::glam::Vec3;
use std::fmt;

/// What a per-line reader returns on a bad line: the message, without the line
/// number ([`for_each_line`] adds it).
pub type Res<T> = Result<T, String>;

/// A bad line: printed as `line N: message`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseError {
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// Calls `each(line_number, bytes)` for every `\n`-separated line of `text`
/// (1-based numbers; a `\r` before the `\n` is left to [`Line::split`], which
/// treats it as white space), stopping at the first error, which gets the line
/// number. O(text).
pub fn for_each_line(
    text: &[u8],
    mut each: impl FnMut(usize, &[u8]) -> Res<()>,
) -> Result<(), ParseError> {
    for (i, raw) in text.split(|&b| b == b'\n').enumerate() {
        let line = i + 1;
        each(line, raw).map_err(|message| ParseError { line, message })?;
    }
    Ok(())
}

/// The fields of one line, at most `MAX` of them, without allocating.
#[derive(Clone, Copy, Debug)]
pub struct Line<'a, const MAX: usize> {
    fields: [&'a str; MAX],
    n: usize,
}

impl<'a, const MAX: usize> Line<'a, MAX> {
    /// Splits a raw line: invalid UTF-8 and more than `MAX` fields are errors;
    /// `#` starts a comment. O(line length).
    pub fn split(raw: &'a [u8]) -> Res<Self> {
        let text = std::str::from_utf8(raw).map_err(|_| "not valid UTF-8".to_string())?;
        let text = text.split('#').next().unwrap_or("");
        let mut fields = [""; MAX];
        let mut n = 0;
        for tok in text.split_ascii_whitespace() {
            if n == MAX {
                return Err(format!("too many fields (at most {MAX})"));
            }
            fields[n] = tok;
            n += 1;
        }
        Ok(Line { fields, n })
    }

    /// The first field (the command), or `None` on a blank or comment line.
    pub fn command(&self) -> Option<&'a str> {
        (self.n > 0).then(|| self.fields[0])
    }

    /// The fields after the command.
    pub fn args(&self) -> &[&'a str] {
        &self.fields[1.min(self.n)..self.n]
    }
}

/// Checks that `cmd` got exactly the fields `names` (the message lists them).
pub fn expect_fields(cmd: &str, args: &[&str], names: &[&str]) -> Res<()> {
    if args.len() == names.len() {
        return Ok(());
    }
    let usage = if names.is_empty() {
        format!("{cmd} takes no fields")
    } else {
        format!("{cmd} expects {} fields ({})", names.len(), names.join(" "))
    };
    Err(format!("{usage}, got {}", args.len()))
}

/// A user id: an unsigned 64-bit integer.
pub fn id(s: &str) -> Res<u64> {
    s.parse()
        .map_err(|_| format!("bad id '{}' (expected an unsigned 64-bit integer)", clip(s)))
}

/// Exactly `N` finite numbers named `names` (the field count checked first).
pub fn numbers<const N: usize>(cmd: &str, args: &[&str], names: &[&str]) -> Res<[f32; N]> {
    expect_fields(cmd, args, names)?;
    let mut v = [0.0; N];
    for ((out, s), name) in v.iter_mut().zip(args).zip(names) {
        let x: f32 = s
            .parse()
            .map_err(|_| format!("bad number '{}' for {name}", clip(s)))?;
        if !x.is_finite() {
            return Err(format!("{name} is not finite ('{}')", clip(s)));
        }
        *out = x;
    }
    Ok(v)
}

/// `X Y Z R` as a sphere the library accepts (finite, radius >= 0).
pub fn sphere(args: &[&str]) -> Res<Sphere> {
    let v = numbers::<4>("sphere", args, &["X", "Y", "Z", "R"])?;
    let s = Sphere::new(Vec3::new(v[0], v[1], v[2]), v[3]);
    s.validate().map_err(|e| e.to_string())?;
    Ok(s)
}

/// A field shortened to 40 characters for an error message.
pub fn clip(s: &str) -> String {
    const MAX: usize = 40;
    match s.char_indices().nth(MAX) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_split_into_command_and_fields() {
        let l = Line::<4>::split(b"  move 1 2.5\t3 # comment\r").unwrap();
        assert_eq!(l.command(), Some("move"));
        assert_eq!(l.args(), ["1", "2.5", "3"]);
        let blank = Line::<4>::split(b" # only a comment").unwrap();
        assert_eq!((blank.command(), blank.args().len()), (None, 0));
        assert!(Line::<2>::split(b"a b c")
            .unwrap_err()
            .contains("at most 2"));
        assert!(Line::<2>::split(b"\xff").unwrap_err().contains("UTF-8"));
    }

    #[test]
    fn errors_name_the_line_and_the_field() {
        let mut seen = Vec::new();
        let e = for_each_line(b"a\nb\nc\n", |n, raw| {
            seen.push(n);
            if raw == b"b" {
                Err("bad b".into())
            } else {
                Ok(())
            }
        })
        .unwrap_err();
        assert_eq!((e.line, e.to_string()), (2, "line 2: bad b".to_string()));
        assert_eq!(seen, [1, 2]);
        let e = numbers::<2>("p", &["1", "x"], &["A", "B"]).unwrap_err();
        assert_eq!(e, "bad number 'x' for B");
        assert_eq!(
            numbers::<1>("p", &["inf"], &["A"]).unwrap_err(),
            "A is not finite ('inf')"
        );
        assert_eq!(
            expect_fields("q", &["1"], &["A", "B"]).unwrap_err(),
            "q expects 2 fields (A B), got 1"
        );
        assert_eq!(clip(&"x".repeat(50)), format!("{}…", "x".repeat(40)));
        assert!(id("-3").unwrap_err().contains("bad id '-3'"));
        assert_eq!(id("18446744073709551615"), Ok(u64::MAX));
    }
}
