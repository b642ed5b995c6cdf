//! Reading a rosbag2 bag stored as MCAP: a folder with `metadata.yaml` naming its `.mcap` files (a split bag
//! has several), a folder with one `.mcap` file, or a bare `.mcap` file. Files are memory-mapped and read
//! message by message; a damaged file is an error that says where it stopped and how to repair it.

use std::path::{Path, PathBuf};

/// A problem with a bag, naming the file and what is wrong.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct BagError {
    pub path: String,
    pub message: String,
}

impl BagError {
    pub fn new(path: &Path, message: impl Into<String>) -> Self {
        Self {
            path: path.display().to_string(),
            message: message.into(),
        }
    }
}

#[derive(serde::Deserialize)]
struct Metadata {
    rosbag2_bagfile_information: Info,
}

#[derive(serde::Deserialize)]
struct Info {
    #[serde(default)]
    storage_identifier: String,
    #[serde(default)]
    relative_file_paths: Vec<String>,
}

/// The MCAP files of the bag at `path`, in order.
pub fn files(path: &Path) -> Result<Vec<PathBuf>, BagError> {
    if !path.exists() {
        return Err(BagError::new(
            path,
            "no such file or folder (give a rosbag2 folder or an .mcap file)",
        ));
    }
    if path.is_file() {
        return Ok(vec![path.to_path_buf()]);
    }
    let meta = path.join("metadata.yaml");
    if meta.exists() {
        let text = std::fs::read_to_string(&meta)
            .map_err(|e| BagError::new(&meta, format!("cannot read: {e}")))?;
        let m: Metadata = serde_saphyr::from_str(&text).map_err(|e| {
            BagError::new(
                &meta,
                format!("not a rosbag2 metadata file (expected `rosbag2_bagfile_information:` with `relative_file_paths`): {e}"),
            )
        })?;
        let info = m.rosbag2_bagfile_information;
        if !info.storage_identifier.is_empty() && info.storage_identifier != "mcap" {
            return Err(BagError::new(
                &meta,
                format!(
                    "storage `{}`: slosh reads MCAP bags; convert this one with `ros2 bag convert` or `rosbags-convert --dst-storage mcap`",
                    info.storage_identifier
                ),
            ));
        }
        if info.relative_file_paths.is_empty() {
            return Err(BagError::new(&meta, "relative_file_paths is empty"));
        }
        return info
            .relative_file_paths
            .iter()
            .map(|f| {
                let p = path.join(f);
                if p.is_file() {
                    Ok(p)
                } else {
                    Err(BagError::new(
                        &meta,
                        format!("lists {f}, which is not in the folder"),
                    ))
                }
            })
            .collect();
    }
    let mut mcaps: Vec<PathBuf> = std::fs::read_dir(path)
        .map_err(|e| BagError::new(path, format!("cannot list: {e}")))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
        .collect();
    mcaps.sort();
    match mcaps.len() {
        0 => Err(BagError::new(
            path,
            "no metadata.yaml and no .mcap file in this folder",
        )),
        1 => Ok(mcaps),
        _ => Err(BagError::new(
            path,
            "several .mcap files and no metadata.yaml saying their order: give one .mcap file",
        )),
    }
}

/// Calls `visit` with every message of the bag's files in stored order; stops at the first error.
pub fn for_each_message(
    files: &[PathBuf],
    mut visit: impl FnMut(&mcap::Message) -> Result<(), BagError>,
) -> Result<(), BagError> {
    for file in files {
        let f = std::fs::File::open(file)
            .map_err(|e| BagError::new(file, format!("cannot open: {e}")))?;
        // SAFETY: the map is read only while this function runs; a bag changed underneath by another
        // process is reported as corrupt by the MCAP reader's checks rather than read as valid.
        let map = unsafe { memmap2::Mmap::map(&f) }
            .map_err(|e| BagError::new(file, format!("cannot map: {e}")))?;
        if !map.starts_with(mcap::MAGIC) {
            return Err(BagError::new(
                file,
                "not an MCAP file (it does not start with the MCAP magic bytes); slosh reads rosbag2 bags stored as MCAP",
            ));
        }
        // A damaged chunk (an impossible size, records that do not fit) ends what is read (the reader would try to allocate what it claims).
        let (readable, damaged) = crate::mcap_bounds::readable(&map);
        let options = if damaged.is_some() {
            mcap::read::Options::IgnoreEndMagic.into()
        } else {
            Default::default()
        };
        let stream = mcap::MessageStream::new_with_options(readable, options).map_err(|e| {
            BagError::new(
                file,
                format!("not an MCAP file ({e}); slosh reads rosbag2 bags stored as MCAP"),
            )
        })?;
        let mut n = 0;
        for next in stream.map(Some).chain(std::iter::once(None)) {
            let cause = match (next, damaged) {
                (Some(Ok(m)), _) => {
                    visit(&m)?;
                    n += 1;
                    continue;
                }
                (None, None) => break,
                (Some(Err(_)) | None, Some(o)) => o.to_string(),
                (Some(Err(e)), None) => e.to_string(),
            };
            return Err(BagError::new(
                    file,
                    format!(
                        "truncated or corrupt after {n} messages ({cause}); `slosh bag repair {}` recovers the messages of its complete chunks into a new bag",
                        // A rosbag2 folder is repaired whole (a split bag's other files' messages too), into a
                        // new folder beside it, not inside it.
                        match file.parent() {
                            Some(dir)
                                if files.len() > 1 || dir.join("metadata.yaml").is_file() =>
                            {
                                dir.display()
                            }
                            _ => file.display(),
                        }
                    ),
                ));
        }
    }
    Ok(())
}
