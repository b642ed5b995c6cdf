//! A CSV table of time series: a header row of column names, then rows of numbers. The time column is the
//! one named `time` (or `t`), else the first. Empty fields and `nan` read as NaN (a dry probe); lines
//! starting with `#` are comments.

use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Where it came from, for messages and legends.
    pub path: String,
    /// Names of the data columns (without the time column), as in the header.
    pub columns: Vec<String>,
    pub time: Vec<f64>,
    /// One vector per data column, as long as `time`.
    pub data: Vec<Vec<f64>>,
}

impl Table {
    /// The values of the column named `name`.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .position(|c| c == name)
            .map(|i| self.data[i].as_slice())
    }
}

/// Reads a table; errors name the file, line and column.
pub fn read(path: &Path) -> Result<Table, String> {
    let p = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| format!("{p}: {e}"))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines
        .next()
        .ok_or_else(|| format!("{p}: empty file (expected a header row: time,<columns>)"))?;
    let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
    if let Some((i, n)) = names
        .iter()
        .enumerate()
        .find(|(i, n)| names[..*i].contains(n))
    {
        return Err(format!(
            "{p}: column {} is named `{n}` like an earlier one: each column needs its own name",
            i + 1
        ));
    }
    let t_col = names
        .iter()
        .position(|n| {
            let n = n.to_ascii_lowercase();
            n == "time" || n == "t" || n.starts_with("time ") || n.starts_with("time_")
        })
        .unwrap_or(0);
    let mut t = Vec::new();
    let mut data = vec![Vec::new(); names.len() - 1];
    for (ln, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != names.len() {
            return Err(format!(
                "{p}:{}: {} fields, the header has {} ({})",
                ln + 1,
                fields.len(),
                names.len(),
                names.join(",")
            ));
        }
        let mut k = 0;
        for (i, f) in fields.iter().enumerate() {
            let v = if f.is_empty() {
                f64::NAN
            } else {
                f.parse::<f64>().map_err(|_| {
                    format!("{p}:{}: column {}: {f:?} is not a number", ln + 1, names[i])
                })?
            };
            if i == t_col {
                if !v.is_finite() {
                    return Err(format!("{p}:{}: the time is {f:?}", ln + 1));
                }
                t.push(v);
            } else {
                data[k].push(v);
                k += 1;
            }
        }
    }
    if t.is_empty() {
        return Err(format!("{p}: no rows after the header"));
    }
    let mut columns = names;
    columns.remove(t_col);
    Ok(Table {
        path: p,
        columns,
        time: t,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> Result<Table, String> {
        let dir = std::env::temp_dir().join(format!("slosh-table-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("t{}.csv", text.len()));
        std::fs::write(&path, text).unwrap();
        let r = read(&path);
        std::fs::remove_file(&path).unwrap();
        r
    }

    #[test]
    fn the_time_column_is_found_by_name_and_gaps_read_as_nan() {
        let t = table("# measured\np1,time,p2\n0.1,0.0,NaN\n0.2,0.5,\n").unwrap();
        assert_eq!(t.columns, ["p1", "p2"]);
        assert_eq!(t.time, [0.0, 0.5]);
        assert_eq!(t.column("p1").unwrap(), [0.1, 0.2]);
        assert!(t.column("p2").unwrap().iter().all(|v| v.is_nan()));
    }

    #[test]
    fn bad_rows_are_named_by_line_and_column() {
        let e = table("time,p1\n0.0,0.1\n0.1,abc\n").unwrap_err();
        assert!(
            e.contains(":3:") && e.contains("p1") && e.contains("abc"),
            "{e}"
        );
        let e = table("time,p1\n0.0\n").unwrap_err();
        assert!(e.contains(":2:") && e.contains("1 fields"), "{e}");
        assert!(table("time,p1\n").unwrap_err().contains("no rows"));
        let e = table("time,p24,p24\n0,1,2\n").unwrap_err();
        assert!(
            e.contains("column 3 is named `p24` like an earlier one"),
            "{e}"
        );
    }
}
