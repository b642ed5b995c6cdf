//! What the commands that write the manual's generated tables share (the convergence and response examples,
//! the validation command): where, when and at which commit a table was measured, and putting a table
//! between its markers (`<!-- NAME:begin -->` … `<!-- NAME:end -->`) in a page.

/// The CPU's model name (`/proc/cpuinfo`), or "unknown CPU".
pub fn machine() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|c| {
            c.lines().find_map(|l| {
                l.strip_prefix("model name")
                    .map(|m| m.trim_start_matches([' ', '\t', ':']).to_string())
            })
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

/// Today's date (UTC, YYYY-MM-DD), or "unknown".
pub fn today() -> String {
    command(&["date", "-u", "+%Y-%m-%d"])
}

/// The checked-out commit (short hash), or "unknown" outside a git work tree.
pub fn commit() -> String {
    command(&["git", "rev-parse", "--short", "HEAD"])
}

fn command(cmd: &[&str]) -> String {
    std::process::Command::new(cmd[0])
        .args(&cmd[1..])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

/// `text` with what stands between the markers of block `name` replaced by `body`; an error naming the
/// missing marker.
pub fn replace_block(text: &str, name: &str, body: &str) -> Result<String, String> {
    let (begin, end) = (
        format!("<!-- {name}:begin -->\n"),
        format!("<!-- {name}:end -->"),
    );
    let a = text
        .find(&begin)
        .ok_or(format!("no {}", begin.trim_end()))?
        + begin.len();
    let b = text[a..].find(&end).ok_or(format!("no {end}"))? + a;
    Ok(format!("{}{body}{}", &text[..a], &text[b..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_block_is_replaced_between_its_markers_only() {
        let page =
            "a\n<!-- t:begin -->\nold\n<!-- t:end -->\nb\n<!-- u:begin -->\nkeep\n<!-- u:end -->\n";
        assert_eq!(
            replace_block(page, "t", "new\n").unwrap(),
            "a\n<!-- t:begin -->\nnew\n<!-- t:end -->\nb\n<!-- u:begin -->\nkeep\n<!-- u:end -->\n"
        );
        assert_eq!(
            replace_block(page, "v", "x").unwrap_err(),
            "no <!-- v:begin -->"
        );
    }
}
