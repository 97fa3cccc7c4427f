//! Finds where a field of a JSON text starts, by its path
//! (`bodies[1].shapes[0].density`): the line and column of a scene-file
//! problem found after parsing, when serde no longer knows positions.

#[derive(Debug, PartialEq, Eq)]
enum Seg {
    Key(String),
    Index(usize),
}

fn segments(path: &str) -> Option<Vec<Seg>> {
    let mut out = Vec::new();
    let mut key = String::new();
    let mut chars = path.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '.' => {
                if !key.is_empty() {
                    out.push(Seg::Key(std::mem::take(&mut key)));
                }
            }
            '[' => {
                if !key.is_empty() {
                    out.push(Seg::Key(std::mem::take(&mut key)));
                }
                let mut n = String::new();
                for d in chars.by_ref() {
                    if d == ']' {
                        break;
                    }
                    n.push(d);
                }
                out.push(Seg::Index(n.parse().ok()?));
            }
            c => key.push(c),
        }
    }
    if !key.is_empty() {
        out.push(Seg::Key(key));
    }
    Some(out)
}

struct Scanner<'a> {
    s: &'a [u8],
    i: usize,
}

impl Scanner<'_> {
    fn ws(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }

    fn eat(&mut self, b: u8) -> bool {
        self.ws();
        if self.s.get(self.i) == Some(&b) {
            self.i += 1;
            true
        } else {
            false
        }
    }

    /// A string at the cursor (after its opening quote), raw escapes kept.
    fn string(&mut self) -> Option<String> {
        let start = self.i;
        while self.i < self.s.len() {
            match self.s[self.i] {
                b'\\' => self.i += 2,
                b'"' => {
                    let raw = std::str::from_utf8(&self.s[start..self.i]).ok()?.to_owned();
                    self.i += 1;
                    return Some(raw);
                }
                _ => self.i += 1,
            }
        }
        None
    }

    fn skip_value(&mut self) -> Option<()> {
        self.ws();
        let mut depth = 0usize;
        loop {
            let b = *self.s.get(self.i)?;
            match b {
                b'"' => {
                    self.i += 1;
                    self.string()?;
                }
                b'{' | b'[' => {
                    depth += 1;
                    self.i += 1;
                }
                b'}' | b']' => {
                    if depth == 0 {
                        return Some(());
                    }
                    depth -= 1;
                    self.i += 1;
                }
                b',' if depth == 0 => return Some(()),
                _ => self.i += 1,
            }
            if depth == 0 && matches!(b, b'"' | b'}' | b']') {
                return Some(());
            }
        }
    }

    fn find(&mut self, target: &[Seg]) -> Option<usize> {
        self.ws();
        let Some((first, rest)) = target.split_first() else {
            return Some(self.i);
        };
        if self.eat(b'{') {
            if self.eat(b'}') {
                return None;
            }
            loop {
                if !self.eat(b'"') {
                    return None;
                }
                let key = self.string()?;
                if !self.eat(b':') {
                    return None;
                }
                if *first == Seg::Key(key) {
                    return self.find(rest);
                }
                self.skip_value()?;
                if !self.eat(b',') {
                    return None;
                }
            }
        } else if self.eat(b'[') {
            let mut k = 0;
            if self.eat(b']') {
                return None;
            }
            loop {
                if *first == Seg::Index(k) {
                    return self.find(rest);
                }
                self.skip_value()?;
                if !self.eat(b',') {
                    return None;
                }
                k += 1;
            }
        } else {
            None
        }
    }
}

/// Line and column (both from 1) where the value at `path` starts in the
/// JSON `text`; `None` when the path is not in it (a default value the
/// file left out: then the nearest enclosing field that is).
#[must_use]
pub fn locate(text: &str, path: &str) -> Option<(usize, usize)> {
    let mut segs = segments(path)?;
    loop {
        let mut sc = Scanner {
            s: text.as_bytes(),
            i: 0,
        };
        if let Some(offset) = sc.find(&segs) {
            let before = &text[..offset];
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            return Some((line, column));
        }
        segs.pop()?;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_nested_fields() {
        let text = "{\n  \"a\": [1, {\"b\": \"x,]}\"}],\n  \"bodies\": [\n    {},\n    {\"shapes\": [ {\"density\": -1} ]}\n  ]\n}";
        assert_eq!(locate(text, "bodies[1].shapes[0].density"), Some((5, 30)));
        assert_eq!(locate(text, "bodies[1]"), Some((5, 5)));
        assert_eq!(locate(text, "a[1].b"), Some((2, 18)));
        // A field the file left out: the enclosing one.
        assert_eq!(locate(text, "bodies[0].shapes"), Some((4, 5)));
        assert_eq!(locate(text, ""), Some((1, 1)));
    }
}
