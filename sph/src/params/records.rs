//! How the lists of records in [`SimParams`](super::SimParams) are written (serde), in the layout a ROS 2
//! parameter file can hold (it has no arrays of structures): probes and pressure sensors as columns
//! (`names`, `x`, `y`, and `z` for the sensors; `y` may be left out in 2D), and bodies, their openings,
//! bulkheads and springs, and the tank's obstacles as maps by name. A case file and the node's parameters
//! are these types' serde form; nothing maps them field by field.

use super::{BodySpec, ProbeSpec, RegionSpec, SensorSpec, SpringSpec};
use serde::de::{DeserializeOwned, Error as _};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::collections::BTreeMap;

/// The rows of columns that must each be as long as `names`, or, the `optional` ones, empty (read as 0):
/// the error names the group `what` and its columns.
fn rows<const N: usize>(
    what: &str,
    names: &[String],
    columns: [(&str, &[f64], bool); N],
) -> Result<Vec<[f64; N]>, String> {
    let n = names.len();
    if columns
        .iter()
        .any(|(_, c, optional)| c.len() != n && !(*optional && c.is_empty()))
    {
        let keys: Vec<String> = std::iter::once("names")
            .chain(columns.iter().map(|c| c.0))
            .map(|k| format!("{what}.{k}"))
            .collect();
        let lengths: Vec<String> = std::iter::once(n)
            .chain(columns.iter().map(|c| c.1.len()))
            .map(|l| l.to_string())
            .collect();
        let optional: Vec<String> = columns
            .iter()
            .filter(|c| c.2)
            .map(|c| format!("; {what}.{} may be omitted in 2D", c.0))
            .collect();
        let (last, rest) = keys.split_last().expect("names and a column");
        return Err(format!(
            "{} and {last} must have the same length (got {}){}",
            rest.join(", "),
            lengths.join(", "),
            optional.concat()
        ));
    }
    Ok((0..n)
        .map(|i| std::array::from_fn(|k| columns[k].1.get(i).copied().unwrap_or(0.0)))
        .collect())
}

/// Probes as the columns `names`, `x`, `y`.
pub mod probes {
    use super::*;

    #[derive(Serialize, Deserialize, Default)]
    #[serde(deny_unknown_fields, default)]
    struct Columns {
        names: Vec<String>,
        x: Vec<f64>,
        y: Vec<f64>,
    }

    pub fn serialize<S: Serializer>(v: &[ProbeSpec], s: S) -> Result<S::Ok, S::Error> {
        Columns {
            names: v.iter().map(|p| p.name.clone()).collect(),
            x: v.iter().map(|p| p.x).collect(),
            y: v.iter().map(|p| p.y).collect(),
        }
        .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<ProbeSpec>, D::Error> {
        let c = Columns::deserialize(d)?;
        let rows = rows("probes", &c.names, [("x", &c.x, false), ("y", &c.y, true)]);
        Ok(c.names
            .into_iter()
            .zip(rows.map_err(D::Error::custom)?)
            .map(|(name, [x, y])| ProbeSpec { name, x, y })
            .collect())
    }
}

/// Pressure sensors as the columns `names`, `x`, `y`, `z`.
pub mod sensors {
    use super::*;

    #[derive(Serialize, Deserialize, Default)]
    #[serde(deny_unknown_fields, default)]
    struct Columns {
        names: Vec<String>,
        x: Vec<f64>,
        y: Vec<f64>,
        z: Vec<f64>,
    }

    pub fn serialize<S: Serializer>(v: &[SensorSpec], s: S) -> Result<S::Ok, S::Error> {
        Columns {
            names: v.iter().map(|p| p.name.clone()).collect(),
            x: v.iter().map(|p| p.x).collect(),
            y: v.iter().map(|p| p.y).collect(),
            z: v.iter().map(|p| p.z).collect(),
        }
        .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<SensorSpec>, D::Error> {
        let c = Columns::deserialize(d)?;
        let columns = [
            ("x", &c.x[..], false),
            ("y", &c.y, true),
            ("z", &c.z, false),
        ];
        let rows = rows("pressure_sensors", &c.names, columns);
        Ok(c.names
            .into_iter()
            .zip(rows.map_err(D::Error::custom)?)
            .map(|(name, [x, y, z])| SensorSpec { name, x, y, z })
            .collect())
    }
}

/// A record whose name is its key in a map by name (its own serde form leaves the name out).
pub trait Named {
    fn name(&self) -> &str;
    fn set_name(&mut self, name: String);
}

macro_rules! named {
    ($($t:ty),*) => {$(
        impl Named for $t {
            fn name(&self) -> &str {
                &self.name
            }
            fn set_name(&mut self, name: String) {
                self.name = name;
            }
        }
    )*};
}
named!(BodySpec, RegionSpec, SpringSpec);

/// Records as a map from their names to the rest of each (in the order of the names).
pub mod by_name {
    use super::*;

    pub fn serialize<T: Named + Serialize, S: Serializer>(
        v: &[T],
        s: S,
    ) -> Result<S::Ok, S::Error> {
        s.collect_map(v.iter().map(|r| (r.name(), r)))
    }

    pub fn deserialize<'de, T: Named + DeserializeOwned, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Vec<T>, D::Error> {
        Ok(BTreeMap::<String, T>::deserialize(d)?
            .into_iter()
            .map(|(name, mut r)| {
                r.set_name(name);
                r
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::super::SimParams;

    /// A case with every kind of record, written and read back: the same parameters, in the columns and
    /// maps of the parameter files.
    #[test]
    fn records_are_written_as_columns_and_maps_by_name_and_read_back() {
        let case = serde_json::json!({
            "dimension": 2,
            "tank": {"length": 0.8, "breadth": 0.25, "height": 0.6},
            "fill": {"height": 0.19, "length": 0.0},
            "particle_spacing": 0.02,
            "fluid": {},
            "gravity": 9.81,
            "solver": {},
            "probes": {"names": ["left", "mid"], "x": [-0.375, 0.0]},
            "pressure_sensors": {"names": ["wall"], "x": [-0.4], "z": [0.05]},
            "bodies": {"barge": {
                "size": [0.2, 0.2, 0.1],
                "wall_thickness": 0.03,
                "position": [0.0, 0.0, 0.1],
                "mass": 5.0,
                "inertia": [0.1, 0.1, 0.1],
                "centre_of_gravity": [0.0, 0.0, 0.05],
                "openings": {"hole": {"centre": [0.0, 0.0, 0.0], "size": [0.04, 0.04, 0.04]}},
                "springs": {"bow": {"attach": [0.1, 0.0, 0.1], "anchor": [0.3, 0.0, 0.1], "stiffness": 10.0}}
            }},
            "obstacles": {"block": {"centre": [0.2, 0.0, 0.02], "size": [0.05, 0.25, 0.04]}}
        });
        let p: SimParams = serde_json::from_value(case).unwrap();
        assert_eq!(p.probes.len(), 2);
        assert_eq!((p.probes[1].name.as_str(), p.probes[1].y), ("mid", 0.0));
        assert_eq!(
            (p.pressure_sensors[0].name.as_str(), p.pressure_sensors[0].z),
            ("wall", 0.05)
        );
        let b = &p.bodies[0];
        assert_eq!(
            (
                b.name.as_str(),
                b.openings[0].name.as_str(),
                b.springs[0].name.as_str()
            ),
            ("barge", "hole", "bow")
        );
        assert_eq!(p.obstacles[0].name, "block");
        let json = serde_json::to_value(&p).unwrap();
        assert_eq!(json["probes"]["names"], serde_json::json!(["left", "mid"]));
        assert_eq!(json["probes"]["y"], serde_json::json!([0.0, 0.0]));
        assert!(json["bodies"]["barge"]["openings"]["hole"].is_object());
        assert!(json["bodies"]["barge"].get("name").is_none());
        assert_eq!(serde_json::from_value::<SimParams>(json).unwrap(), p);
    }

    #[test]
    fn columns_of_different_lengths_are_refused_naming_them() {
        let e = super::probes::deserialize(serde_json::json!({"names": ["a", "b"], "x": [0.1]}))
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("probes.names, probes.x and probes.y"),
            "{e}"
        );
        let e = super::sensors::deserialize(
            serde_json::json!({"names": ["a"], "x": [0.1], "y": [0.0]}),
        )
        .unwrap_err();
        assert!(
            e.to_string().contains(".z must have the same length"),
            "{e}"
        );
    }
}
