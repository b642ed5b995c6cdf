//! What the simulation gives out besides observations: every particle's state (particle frames) and the
//! liquid's positions and velocities, gathered from all ranks on rank 0.

use super::Simulation;
use crate::domain::Domain;
use crate::kernel::Kernel;
use crate::observe::snapshot::Snapshot;
use crate::particles::Fluid;
use crate::vector::to3;

impl<const D: usize, K: Kernel> Simulation<D, K> {
    /// Liquid particle positions in the tank frame as x, y, z (across ranks: all of them on rank 0, in the
    /// order of their ids, none elsewhere).
    pub fn fluid_positions(&self) -> Vec<[f64; 3]> {
        self.fluid_field(|f, i| to3(f.position(i)))
    }

    /// Liquid particle velocities relative to the tank as x, y, z (across ranks as [`Self::fluid_positions`]).
    pub fn fluid_velocities(&self) -> Vec<[f64; 3]> {
        self.fluid_field(|f, i| to3(std::array::from_fn::<f64, D, _>(|k| f.vel[k][i])))
    }

    fn fluid_field(&self, at: impl Fn(&Fluid<D>, usize) -> [f64; 3]) -> Vec<[f64; 3]> {
        let f = &self.state.fluid;
        let Some(dom) = self.state.processes.domain() else {
            return (0..f.len()).map(|i| at(f, i)).collect();
        };
        let mut local = Vec::new();
        for i in (0..f.len()).filter(|&i| f.owned(i)) {
            local.push(f.id[i] as f64);
            local.extend(at(f, i));
        }
        let mut all: Vec<(u32, [f64; 3])> = dom
            .gather(local)
            .iter()
            .flat_map(|v| v.chunks_exact(4))
            .map(|r| (r[0] as u32, [r[1], r[2], r[3]]))
            .collect();
        all.sort_unstable_by_key(|r| r.0);
        all.into_iter().map(|r| r.1).collect()
    }

    /// Every particle's position, velocity, pressure and density now, in the tank frame (changes nothing).
    /// Across ranks: on rank 0, the liquid of all ranks in the order of the ids (one process: in cell order)
    /// and the wall layers with their owners' densities (mirror ghosts: rank 0's own); empty elsewhere.
    pub fn snapshot(&self) -> Snapshot {
        let (f, b) = (&self.state.fluid, &self.state.bound);
        let (nf, nb) = (f.len(), b.len());
        let mut s = Snapshot {
            time: self.state.time,
            dimension: D,
            fluid: nf,
            position: Vec::with_capacity(nf + nb),
            velocity: Vec::with_capacity(nf + nb),
            pressure: Vec::with_capacity(nf + nb),
            density: Vec::with_capacity(nf + nb),
            id: Vec::with_capacity(nf + nb),
        };
        for i in (0..nf).filter(|&i| f.owned(i)) {
            s.position.push(to3(std::array::from_fn::<f32, D, _>(|k| {
                f.pos[k][i] as f32
            })));
            s.velocity.push(to3(std::array::from_fn::<f32, D, _>(|k| {
                f.vel[k][i] as f32
            })));
            let rho = f.rho[i] as f32;
            s.pressure.push(self.scheme.liquid_pressure(&self.state, i));
            s.density.push(rho);
            s.id.push(f.id[i]);
        }
        s.fluid = s.id.len();
        if let Some(dom) = self.state.processes.domain() {
            return self.gather_snapshot(dom, s);
        }
        for j in 0..nb {
            let (x, v) = self.wall_particle(j);
            s.position.push(x);
            s.velocity.push(v);
            let rho = b.rho.get(j).map_or(self.state.eos.rho0, |&r| r as f32);
            let (p, rho) = self.scheme.wall_reading(&self.state, rho);
            s.pressure.push(p);
            s.density.push(rho);
            s.id.push(j as u32);
        }
        s
    }

    /// Position and velocity of boundary particle j now (x, y, z): a floating body's where the body is
    /// (its particles were last placed at the half step), a wall's where it stands.
    fn wall_particle(&self, j: usize) -> ([f32; 3], [f32; 3]) {
        let b = &self.state.bound;
        match b
            .tag
            .get(j)
            .copied()
            .filter(|&t| t != crate::particles::NOT_BODY)
        {
            Some(t) => {
                let (body, i) = self.state.bodies.which[t as usize];
                let (x, v) = self.state.bodies.list[body as usize].particle(i as usize);
                (x.map(|c| c as f32).into(), v.map(|c| c as f32).into())
            }
            None => (
                to3(std::array::from_fn::<f32, D, _>(|k| b.x[k][j])),
                to3(std::array::from_fn::<f32, D, _>(|k| b.v[k][j])),
            ),
        }
    }

    /// Rank 0: the liquid of every rank (in the order of the ids) and the walls with their owners'
    /// densities. Other ranks send theirs and get an empty snapshot.
    fn gather_snapshot(&self, dom: &Domain, mut s: Snapshot) -> Snapshot {
        let b = &self.state.bound;
        // Wall layers carry their owner's density; mirror ghosts differ from rank to rank: rank 0's are
        // written.
        let walls = self
            .state
            .params
            .solver
            .boundary
            .method
            .has_wall_particles();
        let mut local = Vec::with_capacity(s.fluid * 9 + 1);
        local.push(s.fluid as f64);
        for i in 0..s.fluid {
            local.push(s.id[i] as f64);
            local.extend(
                s.position[i]
                    .iter()
                    .chain(&s.velocity[i])
                    .map(|&v| v as f64),
            );
            local.extend([s.pressure[i] as f64, s.density[i] as f64]);
        }
        for j in (0..b.rho.len()).filter(|_| walls) {
            if dom.owns(&self.state.grid, b.x[0][j] as f64) {
                local.extend([j as f64, b.rho[j]]);
            }
        }
        let all = dom.gather(local);
        if !dom.is_root() {
            return Snapshot::default();
        }
        let mut fluid: Vec<&[f64]> = Vec::new();
        let mut wall_rho: Vec<f64> = b.rho.clone();
        for msg in &all {
            let n = msg[0] as usize;
            fluid.extend(msg[1..1 + 9 * n].chunks_exact(9));
            for p in msg[1 + 9 * n..].chunks_exact(2) {
                wall_rho[p[0] as usize] = p[1];
            }
        }
        fluid.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]));
        let f32s = |r: &[f64]| -> [f32; 3] { [r[0] as f32, r[1] as f32, r[2] as f32] };
        s = Snapshot {
            time: s.time,
            dimension: D,
            fluid: fluid.len(),
            id: fluid.iter().map(|r| r[0] as u32).collect(),
            position: fluid.iter().map(|r| f32s(&r[1..4])).collect(),
            velocity: fluid.iter().map(|r| f32s(&r[4..7])).collect(),
            pressure: fluid.iter().map(|r| r[7] as f32).collect(),
            density: fluid.iter().map(|r| r[8] as f32).collect(),
        };
        for j in 0..b.len() {
            let (x, v) = self.wall_particle(j);
            s.position.push(x);
            s.velocity.push(v);
            let rho = wall_rho.get(j).map_or(self.state.eos.rho0, |&r| r as f32);
            let (p, rho) = self.scheme.wall_reading(&self.state, rho);
            s.pressure.push(p);
            s.density.push(rho);
            s.id.push(j as u32);
        }
        s
    }
}
