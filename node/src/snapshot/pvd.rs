//! The time series of particle frames as a ParaView collection (`.pvd`): a time step and a file per frame.
//! It is rewritten after every frame, through a temporary file, so it always lists the frames written so
//! far and a run that stops early still leaves a series ParaView opens.

use std::path::{Path, PathBuf};

/// One frame of the series: its simulation time and its file, relative to the collection's folder.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub time: f64,
    pub file: String,
}

/// The collection file's text.
pub fn to_string(entries: &[Entry]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for e in entries {
        s.push_str(&format!(
            "    <DataSet timestep=\"{:.9}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
            e.time, e.file
        ));
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s
}

pub fn write(path: &Path, entries: &[Entry]) -> std::io::Result<()> {
    let tmp = path.with_extension("pvd.part");
    std::fs::write(&tmp, to_string(entries))?;
    std::fs::rename(&tmp, path)
}

/// The frames a collection lists, with their files' paths (relative ones resolved against its folder).
pub fn read(path: &Path) -> Result<Vec<(f64, PathBuf)>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let attr = |tag: &str, name: &str| -> Option<String> {
        let key = format!("{name}=\"");
        let at = tag.find(&key)? + key.len();
        Some(tag[at..at + tag[at..].find('"')?].to_string())
    };
    let mut out = Vec::new();
    for (k, tag) in text.split("<DataSet").skip(1).enumerate() {
        let tag = &tag[..tag.find('>').unwrap_or(tag.len())];
        let time = attr(tag, "timestep").and_then(|t| t.parse::<f64>().ok());
        let file = attr(tag, "file");
        match (time, file) {
            (Some(t), Some(f)) => out.push((t, dir.join(f))),
            _ => {
                return Err(format!(
                    "{}: data set {} has no timestep or file",
                    path.display(),
                    k + 1
                ))
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_series_reads_back_with_its_paths() {
        let dir = std::env::temp_dir().join(format!("slosh-pvd-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("run.pvd");
        let e = [
            Entry {
                time: 0.0,
                file: "frame_000000.vtu".into(),
            },
            Entry {
                time: 0.05,
                file: "frame_000001.vtu".into(),
            },
        ];
        write(&path, &e).unwrap();
        let r = read(&path).unwrap();
        assert_eq!(r.len(), 2);
        assert_eq!(r[1], (0.05, dir.join("frame_000001.vtu")));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
