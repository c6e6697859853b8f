//! `Method::Auto`: the solver chosen by the system while Jacobi-PCG runs,
//! before any hierarchy is built.

use crate::common::on_threads;
use tet_diffusion::glam::DVec3;
use tet_diffusion::{AutoCosts, Light, Medium, Method, Object, Solver, TetMesh, kuhn_lattice};

/// A cube of `size` mm in `n³` lattice cells of one medium, lit from
/// above.
fn cube(n: usize, size: f64, medium: Medium) -> Object {
    let (p, t) = kuhn_lattice(n, DVec3::ZERO, DVec3::splat(size));
    let mesh = TetMesh::new(&p, &t).unwrap();
    let mut o = Object::homogeneous(mesh, 1.0, medium, 1.3).unwrap();
    o.add_light(Light::Directional {
        to_light: DVec3::new(0.2, 1.0, 0.3),
        irradiance: [1.0; 3],
    })
    .unwrap();
    o
}

/// Ketchup in a 20 mm cube: absorption within a few cells, Jacobi-PCG
/// converges in tens of iterations.
fn short_diffusion() -> Object {
    cube(10, 20.0, Medium::measured("ketchup").unwrap())
}

/// A clear, barely scattering medium (σs′ = 10⁻⁴ /mm, no absorption) in
/// a finely meshed 12 mm cube, solved to 10⁻⁹: nearly insulated and
/// diffusing far, so Jacobi-PCG needs over 200 iterations where
/// V-cycle-PCG needs about 20.
fn long_diffusion() -> Object {
    let clear = Medium {
        sigma_a: [0.0; 3],
        sigma_s_prime: [1e-4; 3],
    };
    let mut o = cube(24, 12.0, clear);
    o.settings.tolerance = 1e-9;
    o
}

/// Costs of a machine where the V-cycle is cheap against a Jacobi-PCG
/// iteration (a faster multigrid, a GPU): a fifth of today's measured
/// costs here.
fn cheap_v_cycle() -> AutoCosts {
    AutoCosts {
        hierarchy: 30.0,
        v_cycle_iteration: 2.5,
        ..AutoCosts::default()
    }
}

/// The iterations each solver needs when forced (the slowest channel).
fn forced_iterations(make: fn() -> Object) -> [f64; 2] {
    [Method::JacobiPcg, Method::VCyclePcg].map(|method| {
        let mut o = make();
        o.settings.method = method;
        let r = o.solve().unwrap();
        r.channels.iter().map(|c| c.iterations).max().unwrap() as f64
    })
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    let peak = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs() / peak))
}

#[test]
fn a_well_conditioned_system_stays_with_jacobi_pcg() {
    let mut o = short_diffusion();
    assert_eq!(o.settings.method, Method::Auto);
    let r = o.solve().unwrap();
    assert_eq!(r.choice.solver, Solver::JacobiPcg, "{}", r.choice);
    assert!(!r.choice.forced);
    if let Some(p) = r.choice.prediction {
        assert!(!p.prefers_v_cycle(), "{p:?}");
    }
    assert_eq!(
        (o.hierarchy_builds(), r.hierarchy_ms, r.levels),
        (0, 0.0, 1)
    );
    assert!(r.channels.iter().all(|c| c.converged()));
}

#[test]
fn an_ill_conditioned_system_picks_what_its_costs_favour() {
    let [jacobi, v_cycle] = forced_iterations(long_diffusion);
    assert!(jacobi > 5.0 * v_cycle, "{jacobi} vs {v_cycle}");
    // With the measured costs the hierarchy does not pay here: Jacobi-PCG
    // stays, and is indeed the cheaper by its forced iterations.
    let today = AutoCosts::default();
    assert!(jacobi < today.hierarchy + today.v_cycle_iteration * v_cycle);
    let mut o = long_diffusion();
    let r = o.solve().unwrap();
    assert_eq!(r.choice.solver, Solver::JacobiPcg, "{}", r.choice);
    assert_eq!(o.hierarchy_builds(), 0);
    // Where the V-cycle is cheap, the same system builds it, and the
    // V-cycle is then indeed the cheaper.
    let cheap = cheap_v_cycle();
    assert!(cheap.hierarchy + cheap.v_cycle_iteration * v_cycle < jacobi);
    let mut o = long_diffusion();
    o.settings.auto_costs = cheap;
    let r = o.solve().unwrap();
    let p = r.choice.prediction.expect("it predicted");
    assert_eq!(r.choice.solver, Solver::VCyclePcg, "{}", r.choice);
    assert!(p.switches() && !p.hierarchy_kept, "{p:?}");
    assert!(r.hierarchy_built && r.levels > 1 && o.hierarchy_builds() == 1);
    assert!(
        r.choice
            .to_string()
            .starts_with("V-cycle-PCG (auto: after ")
    );
    // It went on from Jacobi-PCG's iterate: the report counts both, fewer
    // than Jacobi-PCG alone needs.
    for c in r.channels {
        assert!(c.converged() && c.iterations > p.probe_iterations);
        assert!((c.iterations as f64) < jacobi, "{:?}", r.channels);
    }
    // A light edit re-decides with the kept hierarchy (no second build).
    o.set_light_color(0, [1.1, 0.9, 0.7]).unwrap();
    let again = o.solve().unwrap();
    assert!(!again.hierarchy_built && o.hierarchy_builds() == 1);
    if let Some(p) = again.choice.prediction {
        assert!(p.hierarchy_kept);
    }
}

#[test]
fn forcing_either_solver_gives_the_same_phi() {
    for make in [short_diffusion, long_diffusion] {
        let mut auto = make();
        auto.solve().unwrap();
        for method in [Method::JacobiPcg, Method::VCyclePcg] {
            let mut o = make();
            o.settings.method = method;
            let r = o.solve().unwrap();
            assert!(r.choice.forced);
            let expected = match method {
                Method::JacobiPcg => Solver::JacobiPcg,
                _ => Solver::VCyclePcg,
            };
            assert_eq!(r.choice.solver, expected);
            for c in 0..3 {
                // Both stop at the same relative residual; φ agrees to
                // well within the discretisation's error.
                let e = max_rel(o.phi(c), auto.phi(c));
                assert!(e < 1e-4, "{method:?} channel {c}: {e:e}");
            }
        }
    }
}

#[test]
fn the_choice_is_the_same_on_every_run_and_thread_count() {
    let run = |threads: usize| {
        on_threads(threads, || {
            let mut o = long_diffusion();
            o.settings.auto_costs = cheap_v_cycle();
            let r = o.solve().unwrap();
            (r.choice, r.channels, o.phi(0).to_vec())
        })
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(2));
}

#[test]
fn costs_out_of_range_are_named() {
    let cases = [
        (
            AutoCosts {
                hierarchy: -100.0,
                ..AutoCosts::default()
            },
            "AutoCosts::hierarchy",
        ),
        (
            AutoCosts {
                v_cycle_iteration: f64::INFINITY,
                ..AutoCosts::default()
            },
            "AutoCosts::v_cycle_iteration",
        ),
        (
            AutoCosts {
                v_cycle_rate: 1.0,
                ..AutoCosts::default()
            },
            "AutoCosts::v_cycle_rate",
        ),
        (
            AutoCosts {
                v_cycle_rate: f64::NAN,
                ..AutoCosts::default()
            },
            "AutoCosts::v_cycle_rate",
        ),
    ];
    for (costs, name) in cases {
        let mut o = short_diffusion();
        o.settings.auto_costs = costs;
        let e = o.solve().unwrap_err().to_string();
        assert!(e.contains(name), "{e}");
        let e = o.solve_preview(10, 1e-2).unwrap_err().to_string();
        assert!(e.contains(name), "{e}");
    }
}
