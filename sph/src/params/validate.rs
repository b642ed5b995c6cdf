//! The checks of a case: every field usable, the pieces consistent with each other (the tank holds the
//! liquid, the probes, the sensors, the obstacles and the bodies; the scheme suits the walls). An error names
//! the first unusable field and says what would do.

use super::*;

fn err(field: &str, message: impl Into<String>) -> ParamError {
    ParamError {
        field: field.to_string(),
        message: message.into(),
    }
}

fn positive(field: &str, v: f64) -> Result<(), ParamError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(err(field, format!("must be a positive number, got {v}")))
    }
}

fn non_negative(field: &str, v: f64) -> Result<(), ParamError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(err(field, format!("must be zero or positive, got {v}")))
    }
}

impl SimParams {
    /// Obstacles lie within the tank, are at least a kernel support thick (the liquid must not see through
    /// them) and are made of wall particles (the dynamic boundary).
    fn validate_obstacles(&self) -> Result<(), ParamError> {
        let Some(first) = self.obstacles.first() else {
            return Ok(());
        };
        if !self.solver.boundary.method.has_wall_particles() {
            return Err(err(
                &format!("obstacles.{}", first.name),
                "obstacles are made of wall particles: set solver.boundary.method: dynamic (or mdbc with wcsph)",
            ));
        }
        let support = 2.0 * self.h();
        let (lo, hi) = self.tank.inside();
        let axes: &[usize] = if self.dimension == 2 {
            &[0, 2]
        } else {
            &[0, 1, 2]
        };
        for (i, o) in self.obstacles.iter().enumerate() {
            let f = |field: &str| format!("obstacles.{}.{field}", o.name);
            if o.name.is_empty() || self.obstacles[..i].iter().any(|p| p.name == o.name) {
                return Err(err(
                    "obstacles",
                    format!(
                        "obstacle names must be unique and not empty; got `{}`",
                        o.name
                    ),
                ));
            }
            for (field, v) in [("centre", &o.centre), ("size", &o.size)] {
                if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                    return Err(err(
                        &f(field),
                        format!("element {k} is not a finite number"),
                    ));
                }
            }
            for &k in axes {
                if !(o.size[k] >= support) {
                    return Err(err(
                        &f("size"),
                        format!(
                            "element {k} ({} m) is thinner than the kernel support {support:.4} m: the liquid \
                             would see through the obstacle; make it at least that (or use a smaller \
                             particle_spacing)",
                            o.size[k]
                        ),
                    ));
                }
                let (a, b) = (o.centre[k] - 0.5 * o.size[k], o.centre[k] + 0.5 * o.size[k]);
                if a < lo[k] - 1e-9 || b > hi[k] + 1e-9 {
                    return Err(err(
                        &f("centre"),
                        format!(
                            "the box reaches outside the tank (axis {k}: {a:.4}..{b:.4} m, tank {:.4}..{:.4} m; \
                             the tank frame's origin is the centre of the tank bottom)",
                            lo[k], hi[k]
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Floating bodies need wall particle layers (and with WCSPH its symplectic integrator), each checked
    /// against the tank.
    fn validate_bodies(&self) -> Result<(), ParamError> {
        if let (Some(wm), Some((thickness, _))) = (&self.wave_maker, self.wave_maker_plate()) {
            wm.validate(self.tank.length, thickness, self.particle_spacing)?;
        }
        let field = match (self.bodies.first(), &self.wave_maker) {
            (Some(first), _) => format!("bodies.{}", first.name),
            (None, Some(_)) => "wave_maker".to_string(),
            (None, None) => return Ok(()),
        };
        let s = &self.solver;
        if s.scheme == Scheme::Wcsph && s.integrator != Integrator::Symplectic {
            return Err(err(&field, "floating bodies and wave makers move with the liquid's symplectic steps: set solver.integrator: symplectic (or solver.scheme: dfsph)"));
        }
        if !s.boundary.method.has_wall_particles() {
            return Err(err(
                &field,
                "floating bodies and wave makers are made of wall particles: set solver.boundary.method: dynamic (or mdbc with wcsph)",
            ));
        }
        let support = 2.0 * self.h();
        let (lo, hi) = self.tank.inside();
        for (i, b) in self.bodies.iter().enumerate() {
            let ok = b.name.starts_with(|c: char| c.is_ascii_alphabetic())
                && b.name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !ok || b.name == "wave_maker" || self.bodies[..i].iter().any(|o| o.name == b.name) {
                return Err(err("bodies", format!("body names must be unique, start with a letter and hold only letters, digits and `_` (they become ROS 2 topic names), and `wave_maker` is taken; got `{}`", b.name)));
            }
            b.validate(self.dimension, lo, hi, self.particle_spacing, support)?;
            if let (Some(wm), Some((_, face))) = (&self.wave_maker, self.wave_maker_plate()) {
                let start = b.position[0] - 0.5 * b.size[0];
                let clear = face + 0.5 * wm.stroke + self.particle_spacing;
                if start < clear {
                    return Err(err(&format!("bodies.{}.position", b.name), format!("the box starts at x = {start:.4} m, within the wave maker's reach (its plate's face comes forward to {clear:.4} m with a spacing to spare)")));
                }
            }
        }
        Ok(())
    }

    /// Checks every field; the error names the first unusable one.
    pub fn validate(&self) -> Result<(), ParamError> {
        if self.solver.kernel == KernelKind::Wendland
            && self.solver.kernel_gradient == Some(KernelGradient::ThomasCouchman)
        {
            return Err(err(
                "solver.kernel_gradient",
                "thomas_couchman is for the cubic spline (the Wendland kernel's gradient does not vanish between close particles): leave it unset or set `exact`",
            ));
        }
        if self.solver.scheme == Scheme::Dfsph
            && self.solver.boundary.method != BoundaryMethod::Dynamic
        {
            return Err(err(
                "solver.boundary.method",
                "the dfsph scheme uses the wall particle layers (`dynamic`); `mirror` and `mdbc` are for wcsph",
            ));
        }
        // The dfsph settings are checked whichever the scheme: a case run with wcsph and switched to dfsph
        // later (`--set solver.scheme=dfsph`) must not meet a bad value only then.
        {
            let d = &self.solver.dfsph;
            if !(d.cfl > 0.0 && d.cfl <= 1.0) {
                return Err(err(
                    "solver.dfsph.cfl",
                    format!("must be in (0, 1], got {}", d.cfl),
                ));
            }
            positive("solver.dfsph.dt_max", d.dt_max)?;
            positive("solver.dfsph.max_density_error", d.max_density_error)?;
            positive("solver.dfsph.max_divergence_error", d.max_divergence_error)?;
            if let Some(w) = d.relaxation {
                if !(w > 0.0 && w <= 1.0) {
                    return Err(err(
                        "solver.dfsph.relaxation",
                        format!(
                            "must be in (0, 1] (0.7 keeps a 3D tank at rest still; leave it unset for the default), got {w}"
                        ),
                    ));
                }
            }
            if d.target_iterations > d.max_iterations {
                return Err(err(
                    "solver.dfsph.target_iterations",
                    format!(
                        "must be at most max_iterations ({}), got {}; 0 turns the control off",
                        d.max_iterations, d.target_iterations
                    ),
                ));
            }
            if !(0.0..=1.0).contains(&d.hydrostatic_warm_start) {
                return Err(err(
                    "solver.dfsph.hydrostatic_warm_start",
                    format!(
                        "must be in [0, 1] (0: half the last pressure), got {}",
                        d.hydrostatic_warm_start
                    ),
                ));
            }
            if d.max_iterations == 0 || d.min_iterations > d.max_iterations {
                return Err(err(
                    "solver.dfsph.max_iterations",
                    format!(
                        "must be at least 1 and at least min_iterations ({}), got {}",
                        d.min_iterations, d.max_iterations
                    ),
                ));
            }
        }
        if self.dimension != 2 && self.dimension != 3 {
            return Err(err(
                "dimension",
                format!("must be 2 or 3, got {}", self.dimension),
            ));
        }
        positive("tank.length", self.tank.length)?;
        positive("tank.breadth", self.tank.breadth)?;
        positive("tank.height", self.tank.height)?;
        positive("particle_spacing", self.particle_spacing)?;
        positive("fill_height", self.fill.height)?;
        non_negative("fill_length", self.fill.length)?;
        positive("fluid.density", self.fluid.density)?;
        non_negative("fluid.kinematic_viscosity", self.fluid.kinematic_viscosity)?;
        non_negative("gravity", self.gravity)?;
        let dp = self.particle_spacing;
        if self.fill.height > self.tank.height {
            return Err(err(
                "fill_height",
                format!(
                    "{} m is above the tank height {} m",
                    self.fill.height, self.tank.height
                ),
            ));
        }
        if self.fill.length > self.tank.length {
            return Err(err(
                "fill_length",
                format!(
                    "{} m is longer than the tank ({} m)",
                    self.fill.length, self.tank.length
                ),
            ));
        }
        let min_extent = if self.dimension == 3 {
            self.tank.breadth.min(self.tank.length)
        } else {
            self.tank.length
        };
        if min_extent < 4.0 * dp || self.tank.height < 4.0 * dp {
            return Err(err(
                "particle_spacing",
                format!(
                    "{dp} m is too coarse for the tank: use at most a quarter of its smallest side"
                ),
            ));
        }
        let (liquid, walls) = self.estimated_particles();
        if liquid + walls > MAX_PARTICLES {
            // The solver indexes particles with 32 bits (one of them a flag).
            let finest = dp * ((liquid + walls) / MAX_PARTICLES).powf(1.0 / self.dimension as f64);
            return Err(err(
                "particle_spacing",
                format!(
                    "{dp} m makes about {:.1e} particles, more than the solver can index ({MAX_PARTICLES:.1e}): use a spacing of at least {:.2e} m",
                    liquid + walls,
                    finest
                ),
            ));
        }
        if self.fill.height < 2.0 * dp {
            return Err(err(
                "fill_height",
                format!(
                    "{} m is less than two particle spacings ({dp} m)",
                    self.fill.height
                ),
            ));
        }
        let s = &self.solver;
        if !(s.smoothing_ratio >= 0.9 && s.smoothing_ratio <= 3.0) {
            return Err(err(
                "solver.smoothing_ratio",
                format!("h/dp must be within 0.9..3, got {}", s.smoothing_ratio),
            ));
        }
        if !(s.cfl > 0.0 && s.cfl <= 1.0) {
            return Err(err(
                "solver.cfl",
                format!("must be within (0, 1], got {}", s.cfl),
            ));
        }
        positive("solver.sound_speed_coefficient", s.sound_speed_coefficient)?;
        non_negative("solver.reference_height", s.reference_height)?;
        non_negative("solver.sound_speed", s.sound_speed)?;
        non_negative(
            "solver.artificial_viscosity.alpha",
            s.artificial_viscosity.alpha,
        )?;
        non_negative(
            "solver.artificial_viscosity.beta",
            s.artificial_viscosity.beta,
        )?;
        positive(
            "solver.artificial_viscosity.eta_factor",
            s.artificial_viscosity.eta_factor,
        )?;
        non_negative(
            "solver.artificial_viscosity.boundary_factor",
            s.artificial_viscosity.boundary_factor,
        )?;
        non_negative("solver.density_diffusion.delta", s.density_diffusion.delta)?;
        self.validate_bodies()?;
        self.validate_obstacles()?;
        non_negative("solver.dt_min", s.dt_min)?;
        positive("solver.dt_max", s.dt_max)?;
        if s.verlet_reset_steps == 0 {
            return Err(err("solver.verlet_reset_steps", "must be at least 1"));
        }
        if s.laminar_viscosity && self.fluid.kinematic_viscosity <= 0.0 {
            return Err(err(
                "fluid.kinematic_viscosity",
                "must be positive when solver.laminar_viscosity is on",
            ));
        }
        if self.gravity == 0.0 && s.sound_speed <= 0.0 {
            return Err(err(
                "solver.sound_speed",
                "set an explicit sound speed when gravity is 0",
            ));
        }
        let (hl, hb) = (self.tank.length / 2.0, self.tank.breadth / 2.0);
        for (i, p) in self.probes.iter().enumerate() {
            if !(p.x.abs() < hl) {
                return Err(err(
                    "probes.x",
                    format!(
                        "probe {i} ({}) at x = {} m is outside the tank (|x| < {hl})",
                        p.name, p.x
                    ),
                ));
            }
            if self.dimension == 3 && !(p.y.abs() < hb) {
                return Err(err(
                    "probes.y",
                    format!(
                        "probe {i} ({}) at y = {} m is outside the tank (|y| < {hb})",
                        p.name, p.y
                    ),
                ));
            }
        }
        for (i, p) in self.pressure_sensors.iter().enumerate() {
            let tol = 1e-9;
            if !(p.x.abs() <= hl + tol) {
                return Err(err(
                    "pressure_sensors.x",
                    format!(
                        "sensor {i} ({}) at x = {} m is outside the tank",
                        p.name, p.x
                    ),
                ));
            }
            if self.dimension == 3 && !(p.y.abs() <= hb + tol) {
                return Err(err(
                    "pressure_sensors.y",
                    format!(
                        "sensor {i} ({}) at y = {} m is outside the tank",
                        p.name, p.y
                    ),
                ));
            }
            if !(p.z >= -tol && p.z <= self.tank.height + tol) {
                return Err(err(
                    "pressure_sensors.z",
                    format!(
                        "sensor {i} ({}) at z = {} m is outside the tank",
                        p.name, p.z
                    ),
                ));
            }
            // On an obstacle's face (within half a spacing) it reads that face; deeper, it would be
            // inside the solid.
            let inside = |o: &RegionSpec| {
                let margin = -0.5 * self.particle_spacing;
                if self.dimension == 2 {
                    o.within::<2>([p.x, p.z], margin)
                } else {
                    o.within::<3>([p.x, p.y, p.z], margin)
                }
            };
            if let Some(o) = self.obstacles.iter().find(|o| inside(o)) {
                return Err(err(
                    "pressure_sensors",
                    format!(
                        "sensor {i} ({}) at ({}, {}, {}) m is inside obstacle `{}`: put it on one of the \
                         obstacle's faces (within half a particle spacing) or in the liquid",
                        p.name, p.x, p.y, p.z, o.name
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 2D seed tank at 10 mm, with a probe and a sensor: a valid case.
    fn seed() -> SimParams {
        let tank = TankSpec {
            length: 0.8,
            breadth: 0.25,
            height: 0.6,
        };
        let mut p = SimParams::filled_tank(2, tank, 0.19, 0.01);
        p.probes.push(ProbeSpec {
            name: "p25".into(),
            x: -0.375,
            y: 0.0,
        });
        p.pressure_sensors.push(SensorSpec {
            name: "left".into(),
            x: -0.4,
            y: 0.0,
            z: 0.1,
        });
        p
    }

    #[test]
    fn the_seed_case_is_valid_in_2d_and_3d_with_either_scheme() {
        for (dimension, scheme) in [(2, Scheme::Wcsph), (2, Scheme::Dfsph), (3, Scheme::Dfsph)] {
            let mut p = seed();
            p.dimension = dimension;
            p.particle_spacing = if dimension == 3 { 0.02 } else { 0.01 };
            p.solver.scheme = scheme;
            assert_eq!(p.validate(), Ok(()), "{dimension}D {scheme:?}");
        }
    }

    /// Each unusable setting is refused, and the error names its field.
    #[test]
    fn an_unusable_setting_is_refused_by_its_field_s_name() {
        type Change = fn(&mut SimParams);
        let cases: &[(&str, Change)] = &[
            ("dimension", |p| p.dimension = 4),
            ("tank.length", |p| p.tank.length = -0.8),
            ("tank.breadth", |p| p.tank.breadth = 0.0),
            ("tank.height", |p| p.tank.height = f64::NAN),
            ("particle_spacing", |p| p.particle_spacing = 0.0),
            // Too coarse for the tank: fewer than four spacings across it.
            ("particle_spacing", |p| p.particle_spacing = 0.2),
            // Too fine: more particles than 32-bit indices with a halo bit can number.
            ("particle_spacing", |p| p.particle_spacing = 1e-6),
            ("fill_height", |p| p.fill.height = 0.7),
            ("fill_height", |p| p.fill.height = 0.015),
            ("fill_length", |p| p.fill.length = 0.9),
            ("fill_length", |p| p.fill.length = -0.1),
            ("fluid.density", |p| p.fluid.density = 0.0),
            ("fluid.kinematic_viscosity", |p| {
                p.fluid.kinematic_viscosity = -1e-6
            }),
            ("fluid.kinematic_viscosity", |p| {
                p.solver.laminar_viscosity = true;
                p.fluid.kinematic_viscosity = 0.0;
            }),
            ("gravity", |p| p.gravity = -9.81),
            ("solver.sound_speed", |p| p.gravity = 0.0),
            ("solver.smoothing_ratio", |p| p.solver.smoothing_ratio = 0.5),
            ("solver.cfl", |p| p.solver.cfl = 1.5),
            ("solver.sound_speed_coefficient", |p| {
                p.solver.sound_speed_coefficient = 0.0
            }),
            ("solver.artificial_viscosity.alpha", |p| {
                p.solver.artificial_viscosity.alpha = -0.1
            }),
            ("solver.density_diffusion.delta", |p| {
                p.solver.density_diffusion.delta = -0.1
            }),
            ("solver.dt_max", |p| p.solver.dt_max = 0.0),
            ("solver.verlet_reset_steps", |p| {
                p.solver.verlet_reset_steps = 0
            }),
            ("solver.kernel_gradient", |p| {
                p.solver.kernel = KernelKind::Wendland;
                p.solver.kernel_gradient = Some(KernelGradient::ThomasCouchman);
            }),
            ("solver.boundary.method", |p| {
                p.solver.scheme = Scheme::Dfsph;
                p.solver.boundary.method = BoundaryMethod::Mirror;
            }),
            ("solver.dfsph.cfl", |p| {
                p.solver.scheme = Scheme::Dfsph;
                p.solver.dfsph.cfl = 0.0;
            }),
            ("solver.dfsph.relaxation", |p| {
                p.solver.scheme = Scheme::Dfsph;
                p.solver.dfsph.relaxation = Some(1.5);
            }),
            ("solver.dfsph.max_iterations", |p| {
                p.solver.scheme = Scheme::Dfsph;
                p.solver.dfsph.target_iterations = 0;
                p.solver.dfsph.max_iterations = 0;
            }),
            ("solver.dfsph.hydrostatic_warm_start", |p| {
                p.solver.scheme = Scheme::Dfsph;
                p.solver.dfsph.hydrostatic_warm_start = 1.5;
            }),
            ("probes.x", |p| p.probes[0].x = 0.5),
            ("pressure_sensors.x", |p| p.pressure_sensors[0].x = -0.5),
            ("pressure_sensors.z", |p| p.pressure_sensors[0].z = 0.7),
            ("obstacles.block.centre", |p| {
                p.obstacles.push(RegionSpec {
                    name: "block".into(),
                    centre: [0.0, 0.0, 0.1],
                    size: [1.0, 0.1, 0.1],
                })
            }),
            // Thinner than the kernel support: the liquid would see through it.
            ("obstacles.block.size", |p| {
                p.obstacles.push(RegionSpec {
                    name: "block".into(),
                    centre: [0.0, 0.0, 0.1],
                    size: [0.01, 0.1, 0.1],
                })
            }),
        ];
        for (field, change) in cases {
            let mut p = seed();
            change(&mut p);
            match p.validate() {
                Ok(()) => panic!("accepted a case with an unusable {field}: {p:?}"),
                Err(e) => {
                    assert_eq!(e.field, *field, "{}", e.message);
                    assert!(!e.message.is_empty(), "{field}: an empty message");
                }
            }
        }
    }

    /// A sensor inside an obstacle is refused; one on its face reads that face.
    #[test]
    fn a_sensor_may_sit_on_an_obstacle_s_face_but_not_inside_it() {
        let mut p = seed();
        p.obstacles.push(RegionSpec {
            name: "block".into(),
            centre: [0.0, 0.0, 0.1],
            size: [0.1, 0.25, 0.2],
        });
        p.pressure_sensors[0] = SensorSpec {
            name: "face".into(),
            x: -0.05,
            y: 0.0,
            z: 0.1,
        };
        assert_eq!(p.validate(), Ok(()));
        p.pressure_sensors[0].x = 0.0;
        let e = p.validate().unwrap_err();
        assert_eq!(e.field, "pressure_sensors", "{}", e.message);
        assert!(e.message.contains("block"), "{}", e.message);
    }

    #[test]
    fn the_density_tolerance_is_the_setting_up_to_50_layers_and_falls_with_the_depth_squared_beyond(
    ) {
        let mut p = seed();
        let tol = p.solver.dfsph.max_density_error;
        // 19 layers, and 50.
        assert_eq!(p.density_tolerance(), tol);
        p.particle_spacing = 0.19 / 50.0;
        assert_eq!(p.density_tolerance(), tol);
        // 100 layers: a quarter; 150: a ninth.
        p.particle_spacing = 0.0019;
        assert!((p.density_tolerance() - 0.25 * tol).abs() < 1e-9 * tol);
        p.particle_spacing = 0.19 / 150.0;
        assert!((p.density_tolerance() - tol / 9.0).abs() < 1e-9 * tol);
    }
}
