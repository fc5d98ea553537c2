//! A small scanner of Rust source: finds each `fn` item with the lines it spans, and whether
//! it is test code (inside a `#[cfg(test)]` item). It does not parse Rust: it skips comments,
//! strings, raw strings, chars and lifetimes, then matches braces. `syn` would parse exactly,
//! but enabling its `full` feature for this test would change the features of the `syn` the
//! workspace already builds, and `cargo build -p graspopt` would then recompile after `cargo
//! test --workspace` (which `.ci/run` refuses).

/// A `fn` item found in a file.
#[derive(Debug, Clone, PartialEq)]
pub struct FnSpan {
    /// `Type::name` inside an `impl` or `trait` block, else `name`.
    pub name: String,
    /// The line of the `fn` keyword (1-based).
    pub line: usize,
    /// Lines from the `fn` keyword to the closing brace, both included.
    pub lines: usize,
    /// Inside a `#[cfg(test)]` item.
    pub test: bool,
}

/// What the scanner finds in one file.
#[derive(Debug, Default, PartialEq)]
pub struct Scan {
    /// Every `fn` item with a body, in the order of their `fn` keywords.
    pub fns: Vec<FnSpan>,
    /// The modules declared `#[cfg(test)] mod name;` (their code is in another file).
    pub test_mods: Vec<String>,
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    Punct(char),
    /// `->` (so that its `>` closes no generics).
    Arrow,
    /// A literal: string, char, number. Only its presence matters.
    Lit,
}

/// The tokens of `src` that matter here, each with its line (1-based).
fn tokens(src: &str) -> Vec<(Tok, usize)> {
    let c: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let (mut i, mut line) = (0, 1);
    // Advances over c[from..to], counting the newlines.
    let skip = |from: usize, to: usize, line: &mut usize| {
        *line += c[from..to.min(c.len())]
            .iter()
            .filter(|&&ch| ch == '\n')
            .count();
        to.min(c.len())
    };
    while i < c.len() {
        let ch = c[i];
        let next = c.get(i + 1).copied();
        if ch == '/' && next == Some('/') {
            let end = (i..c.len()).find(|&j| c[j] == '\n').unwrap_or(c.len());
            i = skip(i, end, &mut line);
        } else if ch == '/' && next == Some('*') {
            let end = block_comment_end(&c, i);
            i = skip(i, end, &mut line);
        } else if let Some(end) = raw_string_end(&c, i) {
            out.push((Tok::Lit, line));
            i = skip(i, end, &mut line);
        } else if ch == '"' || (matches!(ch, 'b' | 'c') && next == Some('"')) {
            let start = if ch == '"' { i } else { i + 1 };
            out.push((Tok::Lit, line));
            i = skip(i, string_end(&c, start), &mut line);
        } else if ch == 'b' && next == Some('\'') {
            out.push((Tok::Lit, line));
            i = skip(i, char_end(&c, i + 1).unwrap_or(i + 2), &mut line);
        } else if ch == '\'' {
            match char_end(&c, i) {
                Some(end) => {
                    out.push((Tok::Lit, line));
                    i = skip(i, end, &mut line);
                }
                // A lifetime or a label: skip the quote and the identifier after it.
                None => i = ident_end(&c, i + 1),
            }
        } else if ch == '_' || ch.is_alphabetic() {
            let end = ident_end(&c, i);
            let word: String = c[i..end].iter().collect();
            out.push((Tok::Ident(word), line));
            i = end;
        } else if ch.is_ascii_digit() {
            out.push((Tok::Lit, line));
            i = ident_end(&c, i);
        } else if ch == '-' && next == Some('>') {
            out.push((Tok::Arrow, line));
            i += 2;
        } else {
            if ch == '\n' {
                line += 1;
            } else if !ch.is_whitespace() {
                out.push((Tok::Punct(ch), line));
            }
            i += 1;
        }
    }
    out
}

fn ident_end(c: &[char], from: usize) -> usize {
    (from..c.len())
        .find(|&j| !(c[j] == '_' || c[j].is_alphanumeric()))
        .unwrap_or(c.len())
}

/// The index after the `*/` that closes the comment opened at `from` (comments nest).
fn block_comment_end(c: &[char], from: usize) -> usize {
    let (mut depth, mut j) = (0usize, from);
    while j + 1 < c.len() {
        if c[j] == '/' && c[j + 1] == '*' {
            depth += 1;
            j += 2;
        } else if c[j] == '*' && c[j + 1] == '/' {
            depth -= 1;
            j += 2;
            if depth == 0 {
                return j;
            }
        } else {
            j += 1;
        }
    }
    c.len()
}

/// The index after the closing quote of the string whose opening quote is at `quote`.
fn string_end(c: &[char], quote: usize) -> usize {
    let mut j = quote + 1;
    while j < c.len() {
        match c[j] {
            '\\' => j += 2,
            '"' => return j + 1,
            _ => j += 1,
        }
    }
    c.len()
}

/// At a raw string (`r"..."`, `r#"..."#`, `br"..."`, `cr#"..."#`): the index after its end.
fn raw_string_end(c: &[char], from: usize) -> Option<usize> {
    // The raw string's prefix must start a token, not end an identifier (`for` then `"`).
    if from > 0 && (c[from - 1] == '_' || c[from - 1].is_alphanumeric()) {
        return None;
    }
    let mut j = from;
    if matches!(c.get(j), Some('b' | 'c')) {
        j += 1;
    }
    if c.get(j) != Some(&'r') {
        return None;
    }
    j += 1;
    let hashes = (j..c.len()).take_while(|&k| c[k] == '#').count();
    j += hashes;
    if c.get(j) != Some(&'"') {
        return None;
    }
    j += 1;
    while j < c.len() {
        if c[j] == '"' && (1..=hashes).all(|h| c.get(j + h) == Some(&'#')) {
            return Some(j + 1 + hashes);
        }
        j += 1;
    }
    Some(c.len())
}

/// At a `'`: the index after a char literal (`'a'`, `'\n'`, `'\u{7f}'`, `'{'`), or `None` for
/// a lifetime or a label (`'a`, `'static`, `'outer:`).
fn char_end(c: &[char], quote: usize) -> Option<usize> {
    match c.get(quote + 1)? {
        '\\' => {
            let close = (quote + 3..c.len()).find(|&j| c[j] == '\'')?;
            Some(close + 1)
        }
        _ if c.get(quote + 2) == Some(&'\'') => Some(quote + 3),
        _ => None,
    }
}

/// An open brace and what it opened.
enum Frame {
    /// A `fn` body: index into `Scan::fns`.
    Fn(usize),
    /// An `impl` or `trait` block of this type.
    Named(String),
    Other,
}

/// What the tokens since the last item boundary announce.
#[derive(Default)]
struct Pending {
    /// `fn name` seen at this line and paren depth.
    fn_item: Option<(String, usize, usize)>,
    /// `impl ... Type` or `trait Type`: the type's name once known.
    block: Option<String>,
    /// In the header of an `impl`, before its `{`.
    in_impl_header: bool,
    /// The angle-bracket depth inside an `impl` header (generics).
    angle: usize,
    /// Reading the type's path in an `impl` header (after `impl` or `for`).
    taking: bool,
    /// `#[cfg(test)]` seen: the next item is test code.
    test: bool,
    /// `mod name` seen after `#[cfg(test)]`.
    test_mod: Option<String>,
}

/// Scans one file's source.
pub fn scan(src: &str) -> Scan {
    let toks = tokens(src);
    let mut out = Scan::default();
    // Open braces with their frame, and whether they are test code.
    let mut stack: Vec<(Frame, bool)> = Vec::new();
    let mut p = Pending::default();
    let mut parens = 0usize;
    let mut i = 0;
    while i < toks.len() {
        let (tok, line) = &toks[i];
        let prev = i.checked_sub(1).map(|k| &toks[k].0);
        let in_test = stack.last().is_some_and(|(_, t)| *t);
        match tok {
            Tok::Punct('#') if is_cfg_test(&toks, i) => {
                p.test = true;
                i += 6; // # [ cfg ( test )  then the `]`
            }
            Tok::Ident(w) if w == "fn" && p.fn_item.is_none() => {
                if let Some((Tok::Ident(name), _)) = toks.get(i + 1) {
                    p.fn_item = Some((name.clone(), *line, parens));
                    i += 1;
                }
            }
            Tok::Ident(w) if p.fn_item.is_none() && w == "impl" && item_start(prev) => {
                p.in_impl_header = true;
                p.taking = true;
                p.block = None;
            }
            Tok::Ident(w) if p.fn_item.is_none() && w == "trait" && item_start(prev) => {
                if let Some((Tok::Ident(name), _)) = toks.get(i + 1) {
                    p.block = Some(name.clone());
                    i += 1;
                }
            }
            Tok::Ident(w) if w == "mod" && p.test && item_start(prev) => {
                if let Some((Tok::Ident(name), _)) = toks.get(i + 1) {
                    p.test_mod = Some(name.clone());
                    i += 1;
                }
            }
            Tok::Ident(w) if p.in_impl_header && p.angle == 0 => match w.as_str() {
                "for" => {
                    p.taking = true;
                    p.block = None;
                }
                "where" => p.in_impl_header = false,
                "dyn" | "mut" | "const" | "unsafe" => {}
                _ if p.taking => {
                    // The last segment of a path (`a::b::Type`) is the type's name.
                    p.block = Some(w.clone());
                    p.taking = matches!(toks.get(i + 1), Some((Tok::Punct(':'), _)));
                }
                _ => {}
            },
            Tok::Punct('<') if p.in_impl_header => p.angle += 1,
            Tok::Punct('>') if p.in_impl_header => p.angle = p.angle.saturating_sub(1),
            Tok::Punct('(' | '[') => parens += 1,
            Tok::Punct(')' | ']') => parens = parens.saturating_sub(1),
            Tok::Punct(';') => {
                if p.fn_item.as_ref().is_some_and(|f| f.2 == parens) {
                    p.fn_item = None; // a declaration without a body
                }
                if p.fn_item.is_none() {
                    if let Some(m) = p.test_mod.take() {
                        out.test_mods.push(m);
                    }
                    p = Pending::default();
                }
            }
            Tok::Punct('{') => {
                let test = in_test || (p.test && p.fn_item.as_ref().is_none_or(|f| f.2 == parens));
                let frame = match p.fn_item.take() {
                    Some((name, line, depth)) if depth == parens => {
                        out.fns.push(FnSpan {
                            name: qualified(&stack, name),
                            line,
                            lines: 0,
                            test,
                        });
                        Frame::Fn(out.fns.len() - 1)
                    }
                    other => {
                        p.fn_item = other;
                        match p.block.take() {
                            Some(name) if p.fn_item.is_none() => Frame::Named(name),
                            _ => Frame::Other,
                        }
                    }
                };
                if p.fn_item.is_none() {
                    p = Pending::default();
                }
                stack.push((frame, test));
            }
            Tok::Punct('}') => {
                if let Some((Frame::Fn(k), _)) = stack.pop() {
                    out.fns[k].lines = line + 1 - out.fns[k].line;
                }
                if p.fn_item.is_none() {
                    p = Pending::default();
                }
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// Whether the token before a keyword lets it start an item (`impl` in `-> impl Trait` does not).
fn item_start(prev: Option<&Tok>) -> bool {
    match prev {
        None => true,
        Some(Tok::Punct(c)) => matches!(c, '{' | '}' | ';' | ']' | ')'),
        Some(Tok::Ident(w)) => matches!(w.as_str(), "unsafe" | "pub" | "default" | "crate"),
        Some(_) => false,
    }
}

/// Whether `#[cfg(test)]` starts at token `i`.
fn is_cfg_test(toks: &[(Tok, usize)], i: usize) -> bool {
    let want = [
        Tok::Punct('#'),
        Tok::Punct('['),
        Tok::Ident("cfg".into()),
        Tok::Punct('('),
        Tok::Ident("test".into()),
        Tok::Punct(')'),
        Tok::Punct(']'),
    ];
    toks.len() >= i + want.len() && toks[i..i + want.len()].iter().map(|t| &t.0).eq(want.iter())
}

/// `Type::name` when the innermost named block around the fn is an `impl` or `trait`.
fn qualified(stack: &[(Frame, bool)], name: String) -> String {
    for (frame, _) in stack.iter().rev() {
        match frame {
            Frame::Named(ty) => return format!("{ty}::{name}"),
            Frame::Fn(_) => return name,
            Frame::Other => {}
        }
    }
    name
}
