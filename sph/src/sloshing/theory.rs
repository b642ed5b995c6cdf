//! Linear potential-flow sloshing in a rectangular tank (Faltinsen 1978; Faltinsen & Timokha, *Sloshing*,
//! 2009, ch. 4–5) and the laminar damping of its first mode (Stokes layers: Lamb 1932 §347, Keulegan 1959).
//!
//! Coordinates are the solver's tank frame: x along the tank's length from its centre, z up from its bottom,
//! liquid depth h, pitch θ a rotation about +y (positive θ tilts the apparent gravity towards +x).
//! The liquid's force and moment are those *on the tank* (the solver's wrench), the moment about the tank
//! origin (the centre of the bottom), for the whole breadth.

use std::f64::consts::PI;

/// Odd modes summed in the series (their terms fall as k⁻³ or faster).
const MODES: usize = 400;

/// A rectangular tank with liquid at rest, for linear theory.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tank {
    /// Length along x (the direction of the sloshing), breadth along y, liquid depth, m; gravity, m/s²;
    /// density, kg/m³.
    pub length: f64,
    pub breadth: f64,
    pub depth: f64,
    pub gravity: f64,
    pub density: f64,
}

/// The first mode's laminar damping ratio and where it comes from (shares of the dissipation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaminarDamping {
    /// ζ = D / (2 ω E).
    pub ratio: f64,
    pub floor: f64,
    pub end_walls: f64,
    pub side_walls: f64,
}

impl Tank {
    /// k_n = nπ/L of the n-th mode along the length.
    pub fn wavenumber(&self, n: usize) -> f64 {
        n as f64 * PI / self.length
    }

    /// ω_n = sqrt(g k_n tanh(k_n h)), rad/s.
    pub fn natural_frequency(&self, n: usize) -> f64 {
        let k = self.wavenumber(n);
        (self.gravity * k * (k * self.depth).tanh()).sqrt()
    }

    /// 2π / ω_n, s.
    pub fn natural_period(&self, n: usize) -> f64 {
        2.0 * PI / self.natural_frequency(n)
    }

    /// Mass of the liquid, kg (the whole breadth).
    pub fn liquid_mass(&self) -> f64 {
        self.density * self.length * self.breadth * self.depth
    }

    /// Damping ratio of the first mode by laminar Stokes layers on the wetted walls, kinematic viscosity
    /// `nu`: the mean dissipation per unit area under a tangential slip of amplitude U is
    /// (ρ/2)·sqrt(νω/2)·U²; for η = A cos(kξ) cos ωt (ξ from the −x wall) the slip is
    /// Aω sin(kξ)/sinh(kh) on the floor, Aω sinh(kz)/sinh(kh) on the end walls, and both components of the
    /// potential flow on the side walls (`side_walls`: a 3D tank). The wave's energy is ρgA²LB/4 and
    /// ζ = D/(2ωE). The free surface is taken as clean (no dissipation there).
    pub fn laminar_damping(&self, nu: f64, side_walls: bool) -> LaminarDamping {
        let (l, b, h) = (self.length, self.breadth, self.depth);
        let k = self.wavenumber(1);
        let w = self.natural_frequency(1);
        let s2 = (k * h).sinh().powi(2);
        // Dissipation per unit A²: c · ∫ U²/A² dS, c = (ρ/2) sqrt(νω/2).
        let c = 0.5 * self.density * (nu * w / 2.0).sqrt();
        let floor = c * w * w / s2 * (l / 2.0) * b;
        // Two end walls: ∫0^h sinh²(kz) dz = sinh(2kh)/(4k) − h/2.
        let end = 2.0 * c * w * w / s2 * ((2.0 * k * h).sinh() / (4.0 * k) - h / 2.0) * b;
        // Two side walls: ∫∫ (sin²(kξ) cosh²(kz) + cos²(kξ) sinh²(kz)) dξ dz = (L/2) sinh(2kh)/(2k).
        let side = if side_walls {
            2.0 * c * w * w / s2 * (l / 2.0) * (2.0 * k * h).sinh() / (2.0 * k)
        } else {
            0.0
        };
        let total = floor + end + side;
        let energy = self.density * self.gravity * l * b / 4.0;
        LaminarDamping {
            ratio: total / (2.0 * w * energy),
            floor: floor / total,
            end_walls: end / total,
            side_walls: side / total,
        }
    }

    /// The odd modes' wavenumbers k_m = mπ/L, m = 1, 3, 5, …
    fn odd_modes(&self) -> impl Iterator<Item = f64> + '_ {
        (0..MODES).map(|i| self.wavenumber(2 * i + 1))
    }

    /// Steady response to sway x_T = a sin ωt: the liquid's horizontal force on the tank per unit a, as
    /// F_x = `sway_force(ω)` · a · sin ωt (negative above resonance: in anti-phase),
    /// F = −m ẍ_T [1 + Σ_n 8 tanh(k_n h) ω² / (L² h k_n³ (ω_n² − ω²))] over the odd modes.
    pub fn sway_force(&self, w: f64) -> f64 {
        let (l, h, g) = (self.length, self.depth, self.gravity);
        let sum: f64 = self
            .odd_modes()
            .map(|k| {
                let wn2 = g * k * (k * h).tanh();
                8.0 * (k * h).tanh() * w * w / (l * l * h * k.powi(3) * (wn2 - w * w))
            })
            .sum();
        self.liquid_mass() * w * w * (1.0 + sum)
    }

    /// Steady free-surface elevation (above the rest level, in the tank) at `x` under sway x_T = a sin ωt,
    /// per unit a: η = `sway_elevation(ω, x)` · a · sin ωt, with
    /// η = (ω² a / g) Σ_n [4(−1)^n / (L k_n²)] ω_n²/(ω_n² − ω²) sin(k_n x) (n = 0, 1, …: below resonance the
    /// liquid rises at +x while the tank accelerates towards −x).
    pub fn sway_elevation(&self, w: f64, x: f64) -> f64 {
        let (l, h, g) = (self.length, self.depth, self.gravity);
        let sum: f64 = self
            .odd_modes()
            .enumerate()
            .map(|(n, k)| {
                let wn2 = g * k * (k * h).tanh();
                let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
                4.0 * sign / (l * k * k) * wn2 / (wn2 - w * w) * (k * x).sin()
            })
            .sum();
        w * w / g * sum
    }

    /// Steady response to pitch θ = θ_a sin ωt about the tank origin (the centre of the bottom): the
    /// liquid's moment about y on the tank per unit θ_a, M_y = `pitch_moment(ω)` · θ_a · sin ωt.
    ///
    /// The absolute flow is φ = θ̇ F with F = xz + Φ + χ: xz + Φ is the Stokes–Joukowski potential of the
    /// rotating rectangle (Φ = Σ b_m cos(k_m ξ) sinh(k_m(z − h/2)), b_m = 8 / (L k_m³ cosh(k_m h/2))), χ =
    /// Σ a_m cos(k_m ξ) cosh(k_m z) the sloshing modes set by the free-surface condition −ω²F + gF_z = 0.
    /// The moment on the tank is the weight's moment about the origin minus the rate of change of the
    /// liquid's angular momentum: ρg(L h²/2 + ∫x χ_z(x,h) dx) θ + ω² ρ ∫(z F_x − x F_z) dA θ, times the
    /// breadth. At ω → 0 it is the tilted tank's m g θ (h/2 + L²/(12h)) (the free-surface effect).
    pub fn pitch_moment(&self, w: f64) -> f64 {
        let (l, h, g) = (self.length, self.depth, self.gravity);
        let c = h / 2.0;
        let w2 = w * w;
        // ∫(z F_x − x F_z) dA of xz: ∫(z² − x²) dA.
        let mut inertia = l * h.powi(3) / 3.0 - h * l.powi(3) / 12.0;
        let mut surface = 0.0;
        for k in self.odd_modes() {
            let wn2 = g * k * (k * h).tanh();
            // x = Σ e_m cos(k_m ξ) on the odd modes.
            let e = -4.0 / (l * k * k);
            // b_m cosh(k_m h/2) and b_m sinh(k_m h/2).
            let bc = 8.0 / (l * k.powi(3));
            let bs = bc * (k * c).tanh();
            // a_m cosh(k_m h).
            let a = (w2 * (h * e + bs) + g * e) / (wn2 - w2);
            let sech = 1.0 / (k * h).cosh();
            // Φ: ∫ z Φ_x dA − ∫ x Φ_z dA.
            inertia += -4.0 * bc * (c / k - (k * c).tanh() / (k * k)) + 4.0 * bs / (k * k);
            // χ: ∫ z χ_x dA − ∫ x χ_z dA.
            inertia += -2.0 * a * (h * (k * h).tanh() / k - (1.0 - sech) / (k * k))
                + 2.0 * a * (1.0 - sech) / (k * k);
            // ∫ x χ_z(x, h) dx.
            surface += -2.0 * a * (k * h).tanh() / k;
        }
        self.density * self.breadth * (g * (l * h * h / 2.0 + surface) + w2 * inertia)
    }

    /// The liquid's moment about y on a tank held pitched by θ (small): m g θ (h/2 + L²/(12h)), the weight
    /// through the centroid of the tilted liquid.
    pub fn static_pitch_moment(&self, theta: f64) -> f64 {
        let (l, h) = (self.length, self.depth);
        self.liquid_mass() * self.gravity * theta * (h / 2.0 + l * l / (12.0 * h))
    }

    /// The same at any angle whose level surface z = h + x tan θ (tank frame) stays clear of the floor and
    /// the top: the weight m g (sin θ, 0, −cos θ) in the tank frame through the centroid
    /// (tan θ L²/(12h), h/2 + tan²θ L²/(24h)).
    pub fn tilted_moment(&self, theta: f64) -> f64 {
        let (l, h) = (self.length, self.depth);
        let t = theta.tan();
        let (xc, zc) = (t * l * l / (12.0 * h), h / 2.0 + t * t * l * l / (24.0 * h));
        self.liquid_mass() * self.gravity * (zc * theta.sin() + xc * theta.cos())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seed(depth: f64) -> Tank {
        Tank {
            length: 0.8,
            breadth: 0.25,
            depth,
            gravity: 9.81,
            density: 1000.0,
        }
    }

    #[test]
    fn periods_match_the_published_table() {
        // physics-references: Faltinsen et al. 2000, L 1.73 m, h 0.6 m: T1..T3 = 1.668, 1.066, 0.861 s.
        let t = Tank {
            length: 1.73,
            depth: 0.6,
            ..seed(0.6)
        };
        for (n, want) in [(1, 1.668), (2, 1.066), (3, 0.861)] {
            assert!((t.natural_period(n) - want).abs() < 1e-3, "T{n}");
        }
    }

    #[test]
    fn laminar_damping_of_the_seed_tank() {
        // physics-references: ζ ≈ 0.0007 in 2D, floor 84 %, end walls 16 %.
        let d = seed(0.19).laminar_damping(1e-6, false);
        assert!((d.ratio - 0.0007).abs() < 0.00005, "{d:?}");
        assert!((d.floor - 0.84).abs() < 0.01, "{d:?}");
        let d3 = seed(0.19).laminar_damping(1e-6, true);
        assert!(d3.ratio > 2.0 * d.ratio, "{d3:?}");
    }

    #[test]
    fn slow_sway_moves_the_liquid_as_a_rigid_body_with_a_tilted_surface() {
        let t = seed(0.19);
        let w = 1e-3;
        // Force: −m ẍ (rigid) plus the sloshing part, which vanishes with ω².
        let f = t.sway_force(w) / (w * w);
        assert!((f / t.liquid_mass() - 1.0).abs() < 1e-3);
        // Quasi-static tilt: η at the +x wall = (ω² a/g) L/2, falling as much at the −x wall.
        let eta = t.sway_elevation(w, 0.4) / (w * w / 9.81);
        assert!((eta - 0.4).abs() < 1e-3, "{eta}");
        let eta = t.sway_elevation(w, -0.4) / (w * w / 9.81);
        assert!((eta + 0.4).abs() < 1e-3, "{eta}");
    }

    #[test]
    fn force_changes_sign_through_resonance() {
        let t = seed(0.39);
        let w1 = t.natural_frequency(1);
        assert!(t.sway_force(0.95 * w1) > 3.0 * t.liquid_mass() * w1 * w1);
        assert!(t.sway_force(1.05 * w1) < 0.0);
    }

    #[test]
    fn slow_pitch_is_the_tilted_tank() {
        for h in [0.19, 0.39] {
            let t = seed(h);
            let m = t.pitch_moment(1e-4);
            let s = t.static_pitch_moment(1.0);
            assert!((m / s - 1.0).abs() < 1e-6, "{m} against {s}");
        }
    }

    #[test]
    fn a_small_tilt_is_the_linear_one() {
        let t = seed(0.19);
        let (a, b) = (t.tilted_moment(1e-3), t.static_pitch_moment(1e-3));
        assert!((a / b - 1.0).abs() < 1e-5, "{a} against {b}");
    }

    #[test]
    fn pitch_resonates_at_the_first_mode() {
        let t = seed(0.19);
        let w1 = t.natural_frequency(1);
        let below = t.pitch_moment(0.99 * w1);
        let above = t.pitch_moment(1.01 * w1);
        assert!(below.abs() > 20.0 * t.static_pitch_moment(1.0), "{below}");
        assert!(below.signum() != above.signum());
    }
}
