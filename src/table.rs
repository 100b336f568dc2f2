//! A table of numbers with named columns, written as CSV: the one form of every time series,
//! impact list and metrics table the crate produces.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::PathBuf;

/// A table of `f64` columns rendered as CSV with the shortest round-trip representation
/// (bit-identical text for bit-identical numbers).
#[derive(Clone, Debug, Default)]
pub struct Table {
    /// Column names.
    pub columns: Vec<String>,
    /// Row-major values, `columns.len()` per row.
    pub values: Vec<f64>,
}

impl Table {
    /// An empty table with these columns.
    pub fn new(columns: Vec<String>) -> Self {
        Table {
            columns,
            values: Vec::new(),
        }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        if self.columns.is_empty() {
            0
        } else {
            self.values.len() / self.columns.len()
        }
    }

    /// Row `i`.
    pub fn row(&self, i: usize) -> &[f64] {
        let n = self.columns.len();
        &self.values[i * n..(i + 1) * n]
    }

    /// Index of the column called `name`.
    pub fn column_index(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// All values of column `name`.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.column_index(name)?;
        let n = self.columns.len();
        Some(self.values.iter().skip(j).step_by(n).copied().collect())
    }

    /// The columns called `names`, in that order, read in one pass over the rows (`None` if
    /// one is missing). Each [`column`](Self::column) call reads the whole table, whose rows
    /// are a run's megabytes: a figure taking a dozen columns reads it once this way.
    pub fn columns(&self, names: &[&str]) -> Option<Vec<Vec<f64>>> {
        let index = names
            .iter()
            .map(|name| self.column_index(name))
            .collect::<Option<Vec<usize>>>()?;
        let n = self.columns.len();
        let rows = self.rows();
        let mut out: Vec<Vec<f64>> = index.iter().map(|_| Vec::with_capacity(rows)).collect();
        // A block of rows at a time (kept in the cache), each column taken from it in one
        // strided pass: twice as fast as a push per value row by row. (A table without columns
        // has no rows: `max(1)` only keeps the chunk size legal.)
        const BLOCK_ROWS: usize = 512;
        for block in self.values[..rows * n].chunks(BLOCK_ROWS * n.max(1)) {
            for (column, &j) in out.iter_mut().zip(&index) {
                column.extend(block[j..].iter().step_by(n));
            }
        }
        Some(out)
    }

    /// CSV text; fails on a non-finite value, naming its row and column.
    pub fn to_csv(&self) -> Result<String> {
        let mut out = Vec::with_capacity(self.values.len() * 12 + 256);
        self.write_csv(&mut out)?;
        String::from_utf8(out).map_err(|e| Error::invalid("table", e.to_string()))
    }

    /// Streams the CSV text into `w` (no copy of the table is held); fails on a non-finite
    /// value, naming its row and column.
    pub fn write_csv(&self, w: &mut dyn Write) -> Result<()> {
        let io = |e| Error::Io {
            action: "cannot write CSV",
            path: PathBuf::new(),
            source: e,
        };
        writeln!(w, "{}", self.columns.join(",")).map_err(io)?;
        // Rows gather in a chunk of whole lines, handed to `w` at `CHUNK` bytes or more: a
        // buffered writer passes such a write through without copying it.
        const CHUNK: usize = 1 << 16;
        let n = self.columns.len();
        let mut line: Vec<u8> = Vec::with_capacity(CHUNK + 32 * n + 1);
        let mut buffer = zmij::Buffer::new();
        // (A table without columns has no rows: `max(1)` only keeps the chunk size legal.)
        let rows = &self.values[..self.rows() * n];
        for (i, row) in rows.chunks_exact(n.max(1)).enumerate() {
            for (j, &v) in row.iter().enumerate() {
                if !push_display(&mut line, v, &mut buffer) {
                    return Err(Error::diverged(
                        row[0],
                        crate::error::Divergence::NonFinite {
                            name: self.columns[j].clone(),
                            place: format!("in output row {i}"),
                            value: Some(v),
                        },
                    ));
                }
                // Every number is followed by a comma, the row's last one replaced by the line's
                // end (one store instead of a test per number).
                line.push(b',');
            }
            if let Some(end) = line.last_mut() {
                *end = b'\n';
            }
            if line.len() >= CHUNK {
                w.write_all(&line).map_err(io)?;
                line.clear();
            }
        }
        w.write_all(&line).map_err(io)?;
        Ok(())
    }
}

/// Appends `v` as `format!("{v}")` writes it: the shortest digits that read back to `v`, in
/// positional notation, `-0` for negative zero; `false` (nothing appended) for a non-finite
/// `v`. The digits come from `zmij` (the same shortest round-trip digits as the standard
/// library's, several times faster: the CSV rows are most of a run's output time); only the
/// layout differs, and it is redone here.
fn push_display(out: &mut Vec<u8>, v: f64, buffer: &mut zmij::Buffer) -> bool {
    // Zero first: about a quarter of a run's numbers (free flight's penetration and contact
    // flag, the ideal twin's eccentricity).
    if v == 0.0 {
        out.extend_from_slice(if v.is_sign_negative() { b"-0" } else { b"0" });
        return true;
    }
    // Most of a run's numbers: `zmij` writes those whose shortest digits' decimal exponent is
    // -5 to 15 positionally, as `{}` does but for an integer's `.0`. Their magnitude says so
    // (shortest digits of a number at or above 1e-5 are at or above it, and below 1e16 for
    // one below 1e15), and this test is false for a non-finite number.
    if (1e-5..1e15).contains(&v.abs()) && !may_tie(v) {
        let s = buffer.format_finite(v).as_bytes();
        out.extend_from_slice(s.strip_suffix(b".0").unwrap_or(s));
        return true;
    }
    if !v.is_finite() {
        return false;
    }
    if may_tie(v) {
        use std::io::Write as _;
        let _ = write!(out, "{v}");
        return true;
    }
    let s = buffer.format_finite(v);
    // The exponent's `e` is among the last five bytes when there is one (`e-324` at most).
    let tail = s.len().saturating_sub(5);
    let Some(e) = s.as_bytes()[tail..]
        .iter()
        .rposition(|&b| b == b'e')
        .map(|i| tail + i)
    else {
        // Positional already: `zmij` writes `1.0` where the standard library writes `1`.
        out.extend_from_slice(s.strip_suffix(".0").unwrap_or(s).as_bytes());
        return true;
    };
    let (mantissa, exponent) = (&s[..e], &s[e + 1..]);
    let exponent: i32 = exponent.parse().unwrap_or(0);
    let (sign, mantissa) = match mantissa.strip_prefix('-') {
        Some(m) => (&b"-"[..], m),
        None => (&b""[..], mantissa),
    };
    // `d.ddd` times 10^exponent: the digits (at most 17), and where the point goes after the
    // first.
    let mut buf = [b'0'; 24];
    let mut len = 0;
    for &b in mantissa
        .as_bytes()
        .iter()
        .filter(|b| **b != b'.')
        .take(buf.len())
    {
        buf[len] = b;
        len += 1;
    }
    while len > 1 && buf[len - 1] == b'0' {
        len -= 1;
    }
    let digits = &buf[..len.max(1)];
    let point = exponent + 1;
    out.extend_from_slice(sign);
    if point <= 0 {
        out.extend_from_slice(b"0.");
        out.extend(std::iter::repeat_n(b'0', (-point) as usize));
        out.extend_from_slice(digits);
    } else if (point as usize) < digits.len() {
        out.extend_from_slice(&digits[..point as usize]);
        out.push(b'.');
        out.extend_from_slice(&digits[point as usize..]);
    } else {
        out.extend_from_slice(digits);
        out.extend(std::iter::repeat_n(b'0', point as usize - digits.len()));
    }
    true
}

/// Whether `v`'s shortest digits could be a tie between two candidates: its exact decimal
/// expansion one digit longer than the shortest, ending in 5. The standard library then rounds
/// the tie up and `zmij` to even (`-12280865046728.5625` gives `...728.563` and `...728.562`).
/// It needs an expansion of at most 18 significant digits below the units, so a value with
/// `2^e'` its lowest set bit (`e' < 0`) and `2^top` above it ties only if
/// `top log10(2) - e' <= 18`; such values keep the standard library's text.
fn may_tie(v: f64) -> bool {
    let bits = v.to_bits() & !(1 << 63);
    let (biased, fraction) = ((bits >> 52) as i32, bits & ((1 << 52) - 1));
    let (mantissa, e) = if biased == 0 {
        (fraction, -1074)
    } else {
        (fraction | 1 << 52, biased - 1075)
    };
    if mantissa == 0 {
        return false;
    }
    let lowest = e + mantissa.trailing_zeros() as i32;
    let top = e + 64 - mantissa.leading_zeros() as i32;
    // `(top - 1) log10(2) - lowest <= 18.5` in integers, scaled by 1e5 (one multiply per number
    // instead of two conversions and a float product): `log10(2)` rounded to 0.30103 moves the
    // left side by less than 1e-5 over every `top` (|top| < 1100), well inside the half digit
    // the bound keeps above the 18 a tie needs.
    lowest < 0 && (top - 1) * 30_103 - lowest * 100_000 <= 1_850_000
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Columns read together are the columns read one by one.
    #[test]
    fn columns_in_one_pass_are_the_single_columns() {
        let mut table = Table::new(vec!["a".into(), "b".into(), "c".into()]);
        table.values = (0..30).map(|k| k as f64 * 0.5 - 3.0).collect();
        let got = table.columns(&["c", "a", "c"]).expect("present");
        let one = |n| table.column(n).expect("present");
        assert_eq!(got, vec![one("c"), one("a"), one("c")]);
        assert_eq!(
            got[1],
            (0..10).map(|r| r as f64 * 1.5 - 3.0).collect::<Vec<_>>()
        );
        assert!(table.columns(&["a", "missing"]).is_none());
        assert_eq!(Table::default().columns(&[]), Some(vec![]));
        // Over several blocks of rows, the last one partial.
        table.values = (0..3 * 1300).map(|k| k as f64).collect();
        let got = table.columns(&["b", "c"]).expect("present");
        let one = |n| table.column(n).expect("present");
        assert_eq!(got, vec![one("b"), one("c")]);
        assert_eq!(got[1].len(), 1300);
        assert_eq!(got[1][1299], (3 * 1299 + 2) as f64);
    }

    /// The CSV is the header, then one line a row, each number as `{}` writes it; a non-finite
    /// value fails the table, naming its row and column.
    #[test]
    fn csv_lines_and_a_non_finite_value() {
        let mut table = Table::new(vec!["t_s".into(), "x".into()]);
        table.values = vec![0.0, -0.0, 0.5, 1e-7, 1.0, 12.5];
        assert_eq!(
            table.to_csv().unwrap(),
            "t_s,x\n0,-0\n0.5,0.0000001\n1,12.5\n"
        );
        table.values[5] = f64::NAN;
        let e = table.to_csv().unwrap_err().to_string();
        assert!(e.contains("non-finite `x` in output row 2 (NaN)"), "{e}");
        assert_eq!(Table::new(vec![]).to_csv().unwrap(), "\n");
    }

    /// The CSV's numbers are the standard library's `{}` text, character for character, over
    /// every exponent range `zmij` writes in either notation and on ties.
    #[test]
    fn numbers_are_written_as_display_writes_them() {
        let mut buffer = zmij::Buffer::new();
        let mut check = |v: f64| {
            let mut out = Vec::new();
            assert!(push_display(&mut out, v, &mut buffer));
            assert_eq!(String::from_utf8(out).unwrap(), format!("{v}"), "{v:e}");
        };
        for v in [
            0.0, -0.0, 1.0, -1.0, 0.1, 1e-7, 1.5e-5, 1e15, 1e16, 1.2345e21, 5e-324,
        ] {
            check(v);
        }
        check(f64::MAX);
        check(f64::MIN_POSITIVE);
        // Either side of the magnitudes `zmij` writes positionally (where the layout is
        // taken from its text as it is).
        for edge in [1e-5, 1e15, 1e16] {
            let bits = f64::to_bits(edge);
            for k in 0..64 {
                for v in [f64::from_bits(bits - k), f64::from_bits(bits + k)] {
                    check(v);
                    check(-v);
                }
            }
        }
        // A non-finite number is refused and writes nothing.
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut out = Vec::new();
            assert!(!push_display(&mut out, v, &mut zmij::Buffer::new()));
            assert!(out.is_empty());
        }
        // Random bit patterns (every exponent) and random values at the scales of a run's rows.
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for i in 0..600_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = if i % 3 == 0 {
                f64::from_bits(x)
            } else if i % 3 == 1 {
                // Few mantissa bits: short exact expansions, where the ties are.
                ((x >> 40) as f64) * 2f64.powi((x % 80) as i32 - 50)
            } else {
                let unit = (x >> 11) as f64 / (1u64 << 53) as f64;
                (unit - 0.5) * 10f64.powi((x % 40) as i32 - 25)
            };
            if v.is_finite() {
                check(v);
            }
        }
    }
}
