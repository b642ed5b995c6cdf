//! The description of a floating body: a hollow box of boundary particles with openings (damage), its mass
//! properties, the degrees of freedom it may use and the springs that hold it.
//!
//! Box coordinates: origin at the centre of the box's bottom face, axes parallel to the tank's at the start
//! (x along `size[0]`, y along `size[1]`, z up). A 2D run uses the x and z parts of every triple, and its
//! mass, inertia and spring stiffness are per metre of breadth (as the liquid's are).

use super::ParamError;
use crate::vector::to3;
use serde::{Deserialize, Serialize};

/// A box in box coordinates: an opening (damage) cut from the walls, or an internal wall (a bulkhead or deck
/// that divides the hollow into compartments).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionSpec {
    /// Its key in the map of its kind (`records::by_name`).
    #[serde(skip)]
    pub name: String,
    /// Centre, box coordinates, m.
    pub centre: [f64; 3],
    /// Extent along x, y, z, m (an opening at least the wall thickness across the wall it cuts, a bulkhead at
    /// least the kernel support thick).
    pub size: [f64; 3],
}

/// A linear spring between a point of the body and a fixed anchor (a mooring line).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringSpec {
    /// Its key in the map of its kind (`records::by_name`).
    #[serde(skip)]
    pub name: String,
    /// Where it is attached, box coordinates, m.
    pub attach: [f64; 3],
    /// Where it is anchored, tank frame, m.
    pub anchor: [f64; 3],
    /// N/m (2D: per metre of breadth).
    pub stiffness: f64,
    /// Length at which it pulls nothing, m.
    #[serde(default)]
    pub rest_length: f64,
}

/// A degree of freedom of a body, along or about the tank's axes: `surge` (x), `sway` (y), `heave` (z),
/// `roll` (about x), `pitch` (about y), `yaw` (about z). The axis names `x`, `z`, `rx`, `ry`, `rz` work too
/// (YAML reads a bare `y` as a boolean: write `sway`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Dof {
    #[serde(alias = "x")]
    Surge,
    #[serde(alias = "y")]
    Sway,
    #[serde(alias = "z")]
    Heave,
    #[serde(alias = "rx")]
    Roll,
    #[serde(alias = "ry")]
    Pitch,
    #[serde(alias = "rz")]
    Yaw,
}

impl Dof {
    pub const ALL: [Dof; 6] = [
        Dof::Surge,
        Dof::Sway,
        Dof::Heave,
        Dof::Roll,
        Dof::Pitch,
        Dof::Yaw,
    ];
    pub fn index(self) -> usize {
        self as usize
    }
}

/// A rigid hollow box of boundary particles moved by the liquid (and gravity and springs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Its key in the map of its kind (`records::by_name`).
    #[serde(skip)]
    pub name: String,
    /// Outer length (x), breadth (y; unused in 2D) and height (z), m.
    pub size: [f64; 3],
    /// Thickness of its walls, m (at least the kernel support, 2h, so no liquid sees through a wall).
    pub wall_thickness: f64,
    /// Where the centre of its bottom face starts, tank frame, m.
    pub position: [f64; 3],
    /// kg (2D: per metre of breadth).
    pub mass: f64,
    /// Moments of inertia about its centre of gravity along the box axes, kg·m² (2D: only the y one is used,
    /// per metre of breadth).
    pub inertia: [f64; 3],
    /// Centre of gravity, box coordinates, m.
    pub centre_of_gravity: [f64; 3],
    /// Velocity of the centre of gravity at the start, m/s, and angular velocity, rad/s (tank axes; a free
    /// decay test starts from one).
    #[serde(default)]
    pub velocity: [f64; 3],
    #[serde(default)]
    pub angular_velocity: [f64; 3],
    /// Degrees of freedom held at their start values.
    #[serde(default)]
    pub fixed: Vec<Dof>,
    #[serde(default, with = "super::records::by_name")]
    pub openings: Vec<RegionSpec>,
    /// Internal walls (openings cut them too).
    #[serde(default, with = "super::records::by_name")]
    pub bulkheads: Vec<RegionSpec>,
    #[serde(default, with = "super::records::by_name")]
    pub springs: Vec<SpringSpec>,
}

fn err(field: String, message: impl Into<String>) -> ParamError {
    ParamError {
        field,
        message: message.into(),
    }
}

fn finite3(field: String, v: &[f64; 3]) -> Result<(), ParamError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(err(field, format!("element {i} is not a finite number"))),
        None => Ok(()),
    }
}

impl BodySpec {
    /// Checks the body against the tank (`lo`, `hi`: the tank's inside in x, y, z) and the kernel support;
    /// errors name the field as `bodies.NAME.field`.
    pub fn validate(
        &self,
        dimension: usize,
        lo: [f64; 3],
        hi: [f64; 3],
        dp: f64,
        support: f64,
    ) -> Result<(), ParamError> {
        let f = |field: &str| format!("bodies.{}.{field}", self.name);
        let axes: &[usize] = if dimension == 2 { &[0, 2] } else { &[0, 1, 2] };
        finite3(f("size"), &self.size)?;
        finite3(f("position"), &self.position)?;
        finite3(f("inertia"), &self.inertia)?;
        finite3(f("centre_of_gravity"), &self.centre_of_gravity)?;
        finite3(f("velocity"), &self.velocity)?;
        finite3(f("angular_velocity"), &self.angular_velocity)?;
        for &k in axes {
            if !(self.size[k] > 0.0) {
                return Err(err(f("size"), format!("element {k} must be positive")));
            }
        }
        if !(self.mass.is_finite() && self.mass > 0.0) {
            return Err(err(
                f("mass"),
                format!("must be a positive number, got {}", self.mass),
            ));
        }
        let turning: &[usize] = if dimension == 2 { &[1] } else { &[0, 1, 2] };
        for &k in turning {
            if !(self.inertia[k] > 0.0) {
                return Err(err(
                    f("inertia"),
                    format!("element {k} must be positive (kg·m² about the centre of gravity)"),
                ));
            }
        }
        let t = self.wall_thickness;
        if !(t.is_finite() && t >= support) {
            return Err(err(
                f("wall_thickness"),
                format!(
                    "{t} m is thinner than the kernel support {support:.4} m: the liquid would see through \
                     the walls; use at least that (or a smaller particle_spacing)"
                ),
            ));
        }
        for &k in axes {
            if 2.0 * t + 2.0 * dp > self.size[k] + 1e-12 {
                return Err(err(
                    f("wall_thickness"),
                    format!(
                        "{t} m leaves no room inside a box {} m across",
                        self.size[k]
                    ),
                ));
            }
        }
        for &k in axes {
            let (a, b) = if k == 2 {
                (self.position[2], self.position[2] + self.size[2])
            } else {
                (
                    self.position[k] - 0.5 * self.size[k],
                    self.position[k] + 0.5 * self.size[k],
                )
            };
            if a < lo[k] + dp || b > hi[k] - dp {
                return Err(err(
                    f("position"),
                    format!("the box must start at least a particle spacing inside the tank (axis {k}: {a:.4}..{b:.4} m, tank {:.4}..{:.4} m)", lo[k], hi[k]),
                ));
            }
        }
        // The box in box coordinates: outside faces and the hollow inside the walls.
        let outer = |k: usize| match k {
            2 => (0.0, self.size[2]),
            _ => (-0.5 * self.size[k], 0.5 * self.size[k]),
        };
        let inner = |k: usize| (outer(k).0 + t, outer(k).1 - t);
        let span = |k: usize, (a, b): (f64, f64)| format!("{} {a:.4}..{b:.4}", ["x", "y", "z"][k]);
        let extent = |e: &dyn Fn(usize) -> (f64, f64)| {
            axes.iter()
                .map(|&k| span(k, e(k)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        if axes.iter().any(|&k| {
            let (a, b) = outer(k);
            !(a..=b).contains(&self.centre_of_gravity[k])
        }) {
            return Err(err(
                f("centre_of_gravity"),
                format!(
                    "{:?} m is outside the box ({} m; box coordinates: origin at the centre of its bottom \
                     face, z up)",
                    axes.iter().map(|&k| self.centre_of_gravity[k]).collect::<Vec<_>>(),
                    extent(&outer)
                ),
            ));
        }
        for (group, regions) in [("openings", &self.openings), ("bulkheads", &self.bulkheads)] {
            for o in regions {
                finite3(f(&format!("{group}.{}.centre", o.name)), &o.centre)?;
                finite3(f(&format!("{group}.{}.size", o.name)), &o.size)?;
                if axes.iter().any(|&k| !(o.size[k] > 0.0)) {
                    return Err(err(
                        f(&format!("{group}.{}.size", o.name)),
                        "every extent must be positive",
                    ));
                }
            }
        }
        for o in &self.openings {
            // Through a wall (from outside its outer face past its inner face, on either side, opening
            // into the hollow along the other axes), or through a bulkhead (a duct between compartments).
            let through = axes.iter().any(|&k| {
                o.crosses(axes, k, (outer(k).0, inner(k).0), &inner)
                    || o.crosses(axes, k, (inner(k).1, outer(k).1), &inner)
            });
            let duct = self.bulkheads.iter().any(|b| {
                axes.iter()
                    .any(|&k| o.crosses(axes, k, b.bounds(k), &|m| b.bounds(m)))
            });
            if !(through || duct) {
                return Err(err(
                    f(&format!("openings.{}", o.name)),
                    format!(
                        "does not cut through a wall into the hollow (nor through a bulkhead), so it would \
                         leave the box intact: the region ({} m) must reach from outside a wall's outer face \
                         past its inner face, and overlap the hollow along the other axes (box: {} m, hollow: \
                         {} m; box coordinates: origin at the centre of its bottom face, z up)",
                        extent(&|k| o.bounds(k)),
                        extent(&outer),
                        extent(&inner)
                    ),
                ));
            }
        }
        for s in &self.springs {
            finite3(f(&format!("springs.{}.attach", s.name)), &s.attach)?;
            finite3(f(&format!("springs.{}.anchor", s.name)), &s.anchor)?;
            if !(s.stiffness.is_finite() && s.stiffness >= 0.0) {
                return Err(err(
                    f(&format!("springs.{}.stiffness", s.name)),
                    format!("must be zero or positive, got {}", s.stiffness),
                ));
            }
            if !(s.rest_length.is_finite() && s.rest_length >= 0.0) {
                return Err(err(
                    f(&format!("springs.{}.rest_length", s.name)),
                    format!("must be zero or positive, got {}", s.rest_length),
                ));
            }
        }
        Ok(())
    }

    /// Whether a point in box coordinates lies in one of the openings.
    pub fn in_opening(&self, p: [f64; 3], dimension: usize) -> bool {
        self.openings.iter().any(|o| o.contains(p, dimension))
    }

    /// Whether a point in box coordinates lies in one of the bulkheads.
    pub fn in_bulkhead(&self, p: [f64; 3], dimension: usize) -> bool {
        self.bulkheads.iter().any(|o| o.contains(p, dimension))
    }
}

impl RegionSpec {
    /// Whether `x` (a D-dimensional point, tank frame) lies within this region taken as an obstacle (centre and
    /// size in the tank frame) grown by `margin` on every side (in 2D along x and z).
    pub fn within<const D: usize>(&self, x: [f64; D], margin: f64) -> bool {
        let x = to3(x);
        let axes: &[usize] = if D == 2 { &[0, 2] } else { &[0, 1, 2] };
        axes.iter()
            .all(|&k| (x[k] - self.centre[k]).abs() < 0.5 * self.size[k] + margin)
    }

    /// Its extent along axis `k`, box coordinates, m.
    fn bounds(&self, k: usize) -> (f64, f64) {
        (
            self.centre[k] - 0.5 * self.size[k],
            self.centre[k] + 0.5 * self.size[k],
        )
    }

    /// Whether the region covers the interval `across` along axis `k` and overlaps `window` (an extent per
    /// axis) along the other `axes`: it cuts through a slab from one face to the other.
    fn crosses(
        &self,
        axes: &[usize],
        k: usize,
        (a, b): (f64, f64),
        window: &dyn Fn(usize) -> (f64, f64),
    ) -> bool {
        let (lo, hi) = self.bounds(k);
        lo <= a
            && hi >= b
            && axes.iter().filter(|&&m| m != k).all(|&m| {
                let ((lo, hi), (wa, wb)) = (self.bounds(m), window(m));
                lo < wb && hi > wa
            })
    }

    /// Whether a point in box coordinates lies in the region (2D: ignoring y).
    pub fn contains(&self, p: [f64; 3], dimension: usize) -> bool {
        (0..3)
            .filter(|&k| dimension == 3 || k != 1)
            .all(|k| (p[k] - self.centre[k]).abs() <= 0.5 * self.size[k])
    }
}
