//! Typed results: numbers a validation page states outside its generated tables.
//!
//! A result must come from a run through a generated table, so that `rheosph gallery --check`
//! can hold it to its source. Prose may still state what was set and what was published,
//! written as an assignment: `Wi = 0.7`, `K = 117.78 (Alves et al. 2001, Table 3)`, a list
//! continuing one (`De = 0.25, 0.5 and 1`), or a reference (`Fig. 4.2`, `Table 3.1`). Any
//! other number with a decimal point, an exponent or a percent sign is reported as typed.
//! Integers pass (resolutions, counts, years); code spans, fenced code and link targets are
//! not prose. The rule is a guard rail for the reader's eye, not a proof: `K = 117.9` written
//! as an assignment passes whether it was published or run.

/// A number stated by hand outside the generated tables.
#[derive(Debug, Clone, PartialEq)]
pub struct Typed {
    /// 1-based line of the page.
    pub line: usize,
    /// The number as written.
    pub number: String,
}

/// Words after which a number names a figure, table, equation or section, not a value.
const REFERENCES: [&str; 12] = [
    "Fig.", "Figs.", "Figure", "Figures", "Table", "Tables", "Eq.", "Eqs.", "Section", "Sections",
    "§", "version",
];
/// Signs after which a number is a setting or a published value.
const ASSIGN: [char; 6] = ['=', '≤', '≥', '<', '>', '≡'];
/// What may stand between the numbers of a list that an assignment began.
const LIST: [&str; 9] = [",", "…", "...", "–", "-", "to", "and", "/", "or"];

/// Every typed result of `text` (a page), generated blocks, code and link targets aside.
pub fn typed_numbers(text: &str) -> Vec<Typed> {
    let mut found = Vec::new();
    let (mut generated, mut fenced) = (false, false);
    // Whether the previous line ended in an assignment that this one completes.
    let mut carried = false;
    for (n, line) in text.lines().enumerate() {
        let trimmed = line.trim();
        if trimmed.starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if trimmed.starts_with(super::OPEN) {
            generated = true;
        }
        if trimmed == super::CLOSE {
            generated = false;
            continue;
        }
        if generated || fenced {
            continue;
        }
        let text = prose(line);
        found.extend(in_line(&text, carried).into_iter().map(|number| Typed {
            line: n + 1,
            number,
        }));
        carried = text.trim_end().ends_with(ASSIGN);
    }
    found
}

/// `line` with code spans, link targets and HTML comments blanked out.
fn prose(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut chars = line.chars().peekable();
    let mut prev = ' ';
    while let Some(c) = chars.next() {
        let close = match c {
            '`' => Some('`'),
            '(' if prev == ']' => Some(')'),
            '<' if chars.peek() == Some(&'!') => Some('>'),
            _ => None,
        };
        match close {
            Some(end) => {
                for d in chars.by_ref() {
                    if d == end {
                        break;
                    }
                }
                out.push(' ');
            }
            None => out.push(c),
        }
        prev = c;
    }
    out
}

/// A number token of a line: where it starts and ends (bytes), and whether it reads as a
/// measured value (decimal point, exponent or percent sign).
struct Token {
    start: usize,
    end: usize,
    valued: bool,
}

fn tokens(line: &str) -> Vec<Token> {
    let b = line.as_bytes();
    let mut found = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let glued =
            i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_' || b[i - 1] == b'.');
        if !b[i].is_ascii_digit() || glued || line[..i].ends_with(|c: char| c.is_alphabetic()) {
            i += 1;
            continue;
        }
        let start = i;
        let mut valued = false;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        if i + 1 < b.len() && b[i] == b'.' && b[i + 1].is_ascii_digit() {
            valued = true;
            i += 1;
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
        }
        if i + 1 < b.len() && (b[i] == b'e' || b[i] == b'E') {
            let sign = usize::from(b[i + 1] == b'-' || b[i + 1] == b'+');
            if b.get(i + 1 + sign).is_some_and(u8::is_ascii_digit) {
                valued = true;
                i += 1 + sign;
                while i < b.len() && b[i].is_ascii_digit() {
                    i += 1;
                }
            }
        }
        let rest = &line[i..];
        if rest.starts_with('%') || rest.starts_with(" %") {
            valued = true;
            i += rest.find('%').unwrap_or(0) + 1;
        }
        found.push(Token {
            start,
            end: i,
            valued,
        });
    }
    found
}

/// The typed results of one line of prose; `carried` if the line before ended in an
/// assignment.
fn in_line(line: &str, carried: bool) -> Vec<String> {
    let mut found = Vec::new();
    // Whether the previous number was a setting, a published value or a reference.
    let mut stated = false;
    let mut last_end = 0;
    for t in tokens(line) {
        let before = line[last_end..t.start].trim_end();
        let before = before
            .trim_end_matches(['−', '-', '+', '±', '~', '('])
            .trim_end();
        let word = before.rsplit(char::is_whitespace).next().unwrap_or("");
        let follows_list = stated && LIST.contains(&before.trim()) && last_end > 0;
        stated = before.ends_with(ASSIGN)
            || (carried && last_end == 0 && before.is_empty())
            || follows_list
            || REFERENCES.contains(&word)
            || (!t.valued && stated && before.trim().is_empty());
        if t.valued && !stated {
            found.push(line[t.start..t.end].to_string());
        }
        last_end = t.end;
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Settings, published values, lists, references, integers, code and generated tables
    /// pass; a measured value in prose is reported with its line.
    #[test]
    fn results_in_prose_are_reported_and_settings_are_not() {
        let page = format!(
            "# Cylinder\n\
             At Wi = 0.7 and β = 0.59 (Alves et al. 2001: K = 117.78, Table 3.1), H/δr = 30.\n\
             Runs at De = 0.25, 0.5 and 1; see Fig. 4.2 and `--set scheme.time_step.factor=0.05`.\n\
             The drag is 5.8 % off and moves 3 % with δt; ψ_min = −0.0616 [ref](a/b-0.5.md).\n\
             The centre (x, y) = (0.5, 0.781), and u_c =\n0.25, continued.\n\
             {open} values x -->\n| a | 1.5 % |\n{close}\n\
             ```\nK = 1.234 typed in code\n```\n\
             The ratio is 0.9771.\n",
            open = super::super::OPEN,
            close = super::super::CLOSE
        );
        let found = typed_numbers(&page);
        let numbers: Vec<(usize, &str)> =
            found.iter().map(|t| (t.line, t.number.as_str())).collect();
        assert_eq!(numbers, vec![(4, "5.8 %"), (4, "3 %"), (13, "0.9771")]);
    }
}
