//! One particle frame as a VTK XML unstructured grid (`.vtu`) that ParaView, VTK and meshio open: the
//! particles as points with one vertex cell each, and per point `velocity` (3 components), `pressure`,
//! `density`, `fluid` (1 liquid, 0 boundary) and `id`; the simulation time as the field `TimeValue`.
//! Arrays are inline base64 ("binary" format) with a UInt64 byte-count header, little endian.
//!
//! [`read`] reads back the files [`write()`] makes (for `slosh render`); it is not a general VTK reader.

use base64::engine::general_purpose::STANDARD as B64;
use base64::Engine;
use sph::observe::snapshot::Snapshot;
use std::io::Write;
use std::path::Path;

/// The bytes of one data array: a UInt64 byte count, then the values, each base64-encoded on its own (as
/// VTK writes uncompressed inline arrays).
fn encode(bytes: &[u8]) -> String {
    let mut s = B64.encode((bytes.len() as u64).to_le_bytes());
    s.push_str(&B64.encode(bytes));
    s
}

fn f32s<'a>(v: impl Iterator<Item = &'a f32>) -> Vec<u8> {
    v.flat_map(|x| x.to_le_bytes()).collect()
}

fn array(out: &mut String, ty: &str, name: &str, components: usize, bytes: &[u8]) {
    out.push_str(&format!(
        "        <DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{components}\" format=\"binary\">\n          {}\n        </DataArray>\n",
        encode(bytes)
    ));
}

/// The file's text.
pub fn to_string(s: &Snapshot) -> String {
    let n = s.len();
    let mut out = String::with_capacity(64 * n + 2048);
    out.push_str(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n",
    );
    out.push_str("    <FieldData>\n");
    out.push_str(&format!(
        "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"binary\">\n        {}\n      </DataArray>\n",
        encode(&s.time.to_le_bytes())
    ));
    out.push_str("    </FieldData>\n");
    out.push_str(&format!(
        "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">\n      <Points>\n"
    ));
    array(
        &mut out,
        "Float32",
        "Points",
        3,
        &f32s(s.position.iter().flatten()),
    );
    out.push_str("      </Points>\n      <Cells>\n");
    let ints =
        |f: &dyn Fn(usize) -> i64| (0..n).flat_map(|i| f(i).to_le_bytes()).collect::<Vec<_>>();
    array(&mut out, "Int64", "connectivity", 1, &ints(&|i| i as i64));
    array(&mut out, "Int64", "offsets", 1, &ints(&|i| i as i64 + 1));
    // VTK_VERTEX = 1.
    array(&mut out, "UInt8", "types", 1, &vec![1u8; n]);
    out.push_str("      </Cells>\n      <PointData Scalars=\"pressure\" Vectors=\"velocity\">\n");
    array(
        &mut out,
        "Float32",
        "velocity",
        3,
        &f32s(s.velocity.iter().flatten()),
    );
    array(&mut out, "Float32", "pressure", 1, &f32s(s.pressure.iter()));
    array(&mut out, "Float32", "density", 1, &f32s(s.density.iter()));
    let fluid: Vec<u8> = (0..n).map(|i| u8::from(s.is_fluid(i))).collect();
    array(&mut out, "UInt8", "fluid", 1, &fluid);
    let ids: Vec<u8> = s.id.iter().flat_map(|x| x.to_le_bytes()).collect();
    array(&mut out, "UInt32", "id", 1, &ids);
    out.push_str("      </PointData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    out
}

/// Writes `s` to `path` (through a temporary file, so a reader never sees half a frame).
pub fn write(path: &Path, s: &Snapshot) -> std::io::Result<()> {
    let tmp = path.with_extension("vtu.part");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
    f.write_all(to_string(s).as_bytes())?;
    f.into_inner().map_err(|e| e.into_error())?.sync_data()?;
    std::fs::rename(&tmp, path)
}

/// Why a frame could not be read back.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct ReadError {
    pub path: String,
    pub message: String,
}

/// The value of `attr="..."` in an XML start tag.
fn attribute<'a>(tag: &'a str, attr: &str) -> Option<&'a str> {
    let key = format!(" {attr}=\"");
    let at = tag.find(&key)? + key.len();
    let end = tag[at..].find('"')?;
    Some(&tag[at..at + end])
}

/// The decoded bytes of the data array named `name`.
fn data_array(text: &str, name: &str) -> Result<Vec<u8>, String> {
    let key = format!("Name=\"{name}\"");
    let at = text
        .find(&key)
        .ok_or_else(|| format!("no data array named {name}"))?;
    let start = text[at..].find('>').ok_or("unterminated tag")? + at + 1;
    let end = text[start..]
        .find("</DataArray>")
        .ok_or("unterminated data array")?
        + start;
    let body: String = text[start..end]
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect();
    // The header is 8 bytes: 12 base64 characters.
    if body.len() < 12 {
        return Err(format!("data array {name} is too short"));
    }
    let header = B64
        .decode(&body[..12])
        .map_err(|e| format!("data array {name}: {e}"))?;
    let count =
        u64::from_le_bytes(header.as_slice().try_into().map_err(|_| "bad header")?) as usize;
    let bytes = B64
        .decode(&body[12..])
        .map_err(|e| format!("data array {name}: {e}"))?;
    if bytes.len() != count {
        return Err(format!(
            "data array {name} holds {} bytes, its header says {count}",
            bytes.len()
        ));
    }
    Ok(bytes)
}

/// Reads a frame written by [`write()`].
pub fn read(path: &Path) -> Result<Snapshot, ReadError> {
    let err = |message: String| ReadError {
        path: path.display().to_string(),
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
    let piece = text
        .find("<Piece ")
        .map(|i| &text[i..i + text[i..].find('>').unwrap_or(0)])
        .ok_or_else(|| err("not an unstructured grid written by slosh (no Piece)".into()))?;
    let n: usize = attribute(piece, "NumberOfPoints")
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| err("Piece has no NumberOfPoints".into()))?;
    let get = |name: &str, width: usize| -> Result<Vec<u8>, ReadError> {
        let b = data_array(&text, name).map_err(&err)?;
        if b.len() != n * width {
            return Err(err(format!(
                "data array {name} has {} bytes for {n} points",
                b.len()
            )));
        }
        Ok(b)
    };
    let f32s = |b: Vec<u8>| -> Vec<f32> {
        b.chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect()
    };
    let vec3 =
        |v: Vec<f32>| -> Vec<[f32; 3]> { v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect() };
    let time = data_array(&text, "TimeValue").map_err(&err)?;
    let fluid = get("fluid", 1)?;
    let nf = fluid.iter().take_while(|&&f| f == 1).count();
    if fluid[nf..].iter().any(|&f| f != 0) {
        return Err(err("liquid particles do not come first".into()));
    }
    let position = vec3(f32s(get("Points", 12)?));
    let is_2d = position.iter().all(|p| p[1] == 0.0);
    Ok(Snapshot {
        time: f64::from_le_bytes(
            time.as_slice()
                .try_into()
                .map_err(|_| err("TimeValue is not one Float64".into()))?,
        ),
        dimension: if is_2d { 2 } else { 3 },
        fluid: nf,
        position,
        velocity: vec3(f32s(get("velocity", 12)?)),
        pressure: f32s(get("pressure", 4)?),
        density: f32s(get("density", 4)?),
        id: get("id", 4)?
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    pub fn sample() -> Snapshot {
        Snapshot {
            time: 1.25,
            dimension: 3,
            fluid: 2,
            position: vec![[0.1, 0.2, 0.3], [-0.4, 0.5, 0.6], [0.7, -0.8, 0.0]],
            velocity: vec![[1.0, 2.0, 3.0], [-1.0, 0.0, 0.5], [0.0; 3]],
            pressure: vec![100.0, 2500.5, -3.0],
            density: vec![1000.0, 1001.5, 999.0],
            id: vec![7, 3, 0],
        }
    }

    #[test]
    fn a_frame_reads_back_as_written() {
        let dir = std::env::temp_dir().join(format!("slosh-vtu-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("f.vtu");
        let s = sample();
        write(&path, &s).unwrap();
        assert_eq!(read(&path).unwrap(), s);
        assert!(!dir.join("f.vtu.part").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_damaged_frame_is_refused_with_the_array_named() {
        let dir = std::env::temp_dir().join(format!("slosh-vtu-bad-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("f.vtu");
        let text = to_string(&sample()).replace("Name=\"density\"", "Name=\"dens\"");
        std::fs::write(&path, text).unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(e.contains("f.vtu") && e.contains("density"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
