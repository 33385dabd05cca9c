//! The words of LAMMPS input and data files, each with its place
//! (`file:line:col`), so every import error points at its token.
//!
//! Input scripts follow LAMMPS' own rules (`Input::parse`): `#` starts a
//! comment outside quotes, a line ending in `&` continues on the next,
//! words are separated by blanks, and `"…"`, `'…'` or `"""…"""` quote a
//! word that holds blanks (a Lepton expression); the quotes are removed.
//! Data files have no quoting: `#` starts a comment whose text is kept (a
//! `Masses` line's comment names its type).

/// One word and where it starts (1-based line and column, in characters).
#[derive(Clone, Debug, PartialEq)]
pub struct Word {
    pub text: String,
    pub line: usize,
    pub col: usize,
}

/// One command of a script, or one line of a data file.
#[derive(Clone, Debug)]
pub struct Line {
    pub words: Vec<Word>,
    /// The command's words joined by one blank (quoted words quoted), for notes.
    pub text: String,
    /// The text after `#` (data files).
    pub comment: String,
    pub line: usize,
}

/// A file's name, for messages.
#[derive(Clone, Debug)]
pub struct Source {
    pub name: String,
}

impl Source {
    /// `file:line:col: message` at a word.
    pub fn error(&self, word: &Word, message: impl std::fmt::Display) -> String {
        format!("{}:{}:{}: {message}", self.name, word.line, word.col)
    }

    /// `file:line:col: message` at a place that is not a word (a missing line).
    pub fn at(&self, line: usize, col: usize, message: impl std::fmt::Display) -> String {
        format!("{}:{line}:{col}: {message}", self.name)
    }

    /// `file:line: message` at a line (for notes).
    pub fn at_line(&self, line: usize, message: impl std::fmt::Display) -> String {
        format!("{}:{line}: {message}", self.name)
    }

    /// The number a word holds, or an error saying what was expected.
    pub fn number(&self, word: &Word, what: &str) -> Result<f64, String> {
        word.text
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| self.error(word, format!("found `{}`, expected {what} (a finite number)", clip(&word.text))))
    }

    /// The non-negative integer a word holds.
    pub fn count(&self, word: &Word, what: &str) -> Result<u64, String> {
        word.text.parse::<u64>().map_err(|_| self.error(word, format!("found `{}`, expected {what} (a whole number)", clip(&word.text))))
    }
}

/// At most 60 characters of a token, for messages.
pub fn clip(text: &str) -> String {
    if text.chars().count() <= 60 {
        text.to_string()
    } else {
        text.chars().take(57).collect::<String>() + "..."
    }
}

/// The commands of an input script.
pub fn script_lines(text: &str) -> Result<Vec<Line>, (usize, usize, String)> {
    let mut out = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    let mut k = 0;
    while k < lines.len() {
        let first = k + 1;
        let mut words = Vec::new();
        loop {
            let (mut line_words, continues) = split_script_line(lines[k], k + 1)?;
            words.append(&mut line_words);
            k += 1;
            if !continues || k >= lines.len() {
                break;
            }
        }
        if !words.is_empty() {
            // Blanks collapsed and quotes restored: the command as notes quote it.
            let text = words
                .iter()
                .map(
                    |w: &Word| {
                        if w.text.contains(char::is_whitespace) || w.text.is_empty() {
                            format!("\"{}\"", w.text)
                        } else {
                            w.text.clone()
                        }
                    },
                )
                .collect::<Vec<_>>()
                .join(" ");
            out.push(Line { words, text, comment: String::new(), line: first });
        }
    }
    Ok(out)
}

/// The words of one physical script line, and whether it ends in `&`.
fn split_script_line(raw: &str, line: usize) -> Result<(Vec<Word>, bool), (usize, usize, String)> {
    let chars: Vec<char> = raw.chars().collect();
    let mut words = Vec::new();
    let mut k = 0;
    let mut end = chars.len();
    while k < chars.len() {
        let c = chars[k];
        if c.is_whitespace() {
            k += 1;
            continue;
        }
        if c == '#' {
            end = k;
            break;
        }
        let col = k + 1;
        let mut text = String::new();
        if c == '"' || c == '\'' {
            let quote: Vec<char> = if chars[k..].starts_with(&['"', '"', '"']) { vec!['"'; 3] } else { vec![c] };
            k += quote.len();
            let close = (k..chars.len()).find(|&m| chars[m..].starts_with(&quote));
            let Some(close) = close else {
                return Err((
                    line,
                    col,
                    format!("found an unclosed {} quote, expected the closing quote on this line", quote.iter().collect::<String>()),
                ));
            };
            text.extend(&chars[k..close]);
            k = close + quote.len();
        } else {
            while k < chars.len() && !chars[k].is_whitespace() {
                text.push(chars[k]);
                k += 1;
            }
        }
        words.push(Word { text, line, col });
    }
    let body: String = chars[..end].iter().collect();
    let continues = words.last().is_some_and(|w| w.text == "&") && body.trim_end().ends_with('&');
    if continues {
        words.pop();
    }
    Ok((words, continues))
}

/// The lines of a data file after its title line: words (split on blanks)
/// and comment.
pub fn data_lines(text: &str) -> Vec<Line> {
    let mut out = Vec::new();
    for (n, raw) in text.lines().enumerate().skip(1) {
        let (body, comment) = raw.split_once('#').map_or((raw, ""), |(b, c)| (b, c.trim()));
        let mut words: Vec<Word> = Vec::new();
        let mut previous_blank = true;
        for (k, c) in body.chars().enumerate() {
            if c.is_whitespace() {
                previous_blank = true;
                continue;
            }
            if previous_blank {
                words.push(Word { text: String::new(), line: n + 1, col: k + 1 });
            }
            words.last_mut().expect("pushed").text.push(c);
            previous_blank = false;
        }
        out.push(Line { words, text: body.trim().to_string(), comment: comment.to_string(), line: n + 1 });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn script_words_know_their_place_quotes_comments_and_continuations() {
        let lines =
            script_lines("units lj # comment\n\nbond_coeff 1 lepton 1.5 \"k*r^2; k=2\" &\n   # note\npair_coeff * * 1 1\n").unwrap();
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0].words.len(), 2);
        let w = &lines[1].words;
        assert_eq!(w[4], Word { text: "k*r^2; k=2".into(), line: 3, col: 25 });
        assert_eq!(lines[1].line, 3);
        // The continuation line held only a comment: the command ends there.
        assert_eq!(lines[2].words[0], Word { text: "pair_coeff".into(), line: 5, col: 1 });
        let err = script_lines("x\nbond_coeff 1 \"open\n").unwrap_err();
        assert_eq!((err.0, err.1), (2, 14));
    }

    #[test]
    fn data_words_know_their_place_and_keep_comments() {
        let lines = data_lines("title\n 2 atoms\n1 1.0  # actin filament\n");
        assert_eq!(lines[0].words[1], Word { text: "atoms".into(), line: 2, col: 4 });
        assert_eq!(lines[1].comment, "actin filament");
        assert_eq!(lines[1].words[1].col, 3);
    }
}
