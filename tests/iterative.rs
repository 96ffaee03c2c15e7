//! The iterative solver (multigrid conjugate gradients) against the direct one: the same
//! answers, warm starts that save iterations, mechanisms still named, and a fallback when
//! conjugate gradients cannot reach their tolerance.

use linkage::linkage::generators::lattice_body;
use linkage::linkage::{Body, BodySolver, Kinematics, SolverChoice};
use linkage::scene::{load_scene, Simulation, World};

/// Every displacement of every step, flattened.
fn displacements(world: &World) -> Vec<f64> {
    let mut sim = Simulation::new(world).unwrap();
    let mut out = Vec::new();
    for step in 0..=world.steps {
        let (result, _) = sim.step(step).unwrap();
        for b in &result.bodies {
            out.extend(b.displacements.iter().flatten());
        }
    }
    out
}

fn with_solver(world: &World, choice: SolverChoice) -> World {
    let mut w = world.clone();
    for b in &mut w.bodies {
        b.solver.choice = choice;
    }
    w
}

fn max_relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().map(|v| v.abs()).fold(0.0, f64::max);
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / scale
}

/// Iterative and direct answers agree to 1e-8 (of the largest displacement) on every bundled
/// scene the iterative solver can take (not arc-length paths or contact, which factor).
#[test]
fn bundled_scenes_agree_with_the_direct_solver() {
    let mut scenes: Vec<_> = std::fs::read_dir("scenes")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    let mut compared = 0;
    for path in scenes {
        let mut world = load_scene(&path).unwrap();
        // Arc-length paths need a factorization; contact scenes solve all bodies in one
        // coupled Newton system that is factored directly; breaking bodies keep their factor.
        if world.has_contact()
            || world.bodies.iter().any(|b| {
                b.newton.path != linkage::linkage::PathMethod::Schedules
                    || linkage::linkage::fracture::breaks_members(b)
            })
        {
            continue;
        }
        for b in &mut world.bodies {
            // Both solvers converge Newton further than the comparison needs.
            b.newton.tolerance = 1e-10;
        }
        let direct = displacements(&with_solver(&world, SolverChoice::Direct));
        let iterative_world = with_solver(&world, SolverChoice::Iterative);
        let sim = Simulation::new(&iterative_world).unwrap();
        assert!(
            sim.sizes().iter().all(|s| s.solver == "iterative"),
            "{}",
            path.display()
        );
        drop(sim);
        let iterative = displacements(&iterative_world);
        let diff = max_relative_difference(&iterative, &direct);
        assert!(diff <= 1e-8, "{}: {diff:e}", path.display());
        compared += 1;
    }
    assert!(compared >= 6, "{compared}");
}

/// The same on lattices of several sizes (three multigrid levels on the largest).
#[test]
fn lattices_agree_with_the_direct_solver() {
    for cells in [[3, 3, 4], [6, 5, 8], [10, 10, 14]] {
        let mut body = lattice_body(cells).unwrap();
        let solve = |body: &Body| {
            let mut s = BodySolver::new(body).unwrap();
            let state = s.solve_step(body, 1, 1).unwrap();
            (
                state
                    .displacements
                    .iter()
                    .flat_map(|u| u.iter().copied())
                    .collect::<Vec<_>>(),
                s.solver_used(),
            )
        };
        body.solver.choice = SolverChoice::Direct;
        let (direct, used) = solve(&body);
        assert_eq!(used, "direct");
        body.solver.choice = SolverChoice::Iterative;
        let (iterative, used) = solve(&body);
        assert_eq!(used, "iterative");
        let diff = max_relative_difference(&iterative, &direct);
        assert!(diff <= 1e-8, "{cells:?}: {diff:e}");
    }
}

/// A multi-step large-displacement run: warm starts (each Newton correction solved as the new
/// displacement from the previous iterate, each solve started from the best combination of
/// recent solutions under the current tangent) save at least half of the conjugate-gradient
/// iterations of cold starts (each solve from zero to 1e-10 of its own right-hand side), with
/// the same Newton path for both.
#[test]
fn warm_starts_reduce_iterations_over_a_run() {
    let run = |warm: bool| {
        let mut body = lattice_body([8, 8, 20]).unwrap();
        // Push the top sideways hard enough that large and linear differ.
        for l in &mut body.loads {
            l.force *= 100.0;
        }
        body.kinematics = Kinematics::Large;
        body.solver.choice = SolverChoice::Iterative;
        body.solver.iterative.warm_start = warm;
        let mut s = BodySolver::new(&body).unwrap();
        let mut total = 0;
        let mut last = Vec::new();
        for step in 1..=6 {
            let state = s.solve_step(&body, step, 6).unwrap();
            total += state.linear_iterations;
            last = state.displacements;
        }
        (total, last)
    };
    let (warm, a) = run(true);
    let (cold, b) = run(false);
    eprintln!("conjugate-gradient iterations over the run: warm {warm}, cold {cold}");
    let scale = b.iter().map(|u| u.norm()).fold(0.0, f64::max);
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).norm() <= 1e-7 * scale);
    }
    // Measured 91 against 230 (8×8×20 cells, 6 steps): 60 % fewer. Cold takes 15 or 16
    // iterations a solve, and Newton makes 2 solves a step once the path can be extrapolated
    // (4 and 3 in the first two steps); warm needs a handful a solve from the third step on.
    assert!((200..=260).contains(&cold), "cold {cold} iterations");
    assert!(warm <= 105, "warm {warm} iterations");
    assert!(
        2 * warm <= cold,
        "warm {warm} vs cold {cold} iterations: less than half saved"
    );
}

/// A mechanism is still named when the iterative solver was asked for: conjugate gradients
/// cannot converge on it, and the direct fallback names the nodes.
#[test]
fn a_mechanism_is_reported_with_the_iterative_solver() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.nodes"), "1 1\n0 1\n0 0\n1 0\n").unwrap();
    std::fs::write(dir.path().join("s.links"), "1 4\n1 2\n2 3\n3 4\n").unwrap();
    let scene = dir.path().join("m.toml");
    std::fs::write(
        &scene,
        "name = \"m\"\n[[materials]]\nname = \"s\"\nyoungs_modulus = 1e9\narea = 1e-4\n[[bodies]]\nname = \"sq\"\nnodes = \"s.nodes\"\nlinks = \"s.links\"\nsolver = \"iterative\"\n[[bodies.supports]]\nnodes = [3]\nfix = [\"x\", \"y\"]\n[[bodies.supports]]\nnodes = [4]\nfix = [\"y\"]\n[[bodies.loads]]\nnodes = [2]\nforce = [10.0, 0.0]\n",
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    let message = match Simulation::new(&world) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("a mechanism was solved"),
    };
    assert!(
        message.contains("mechanism") && message.contains("1 (x"),
        "{message}"
    );
}

/// A tolerance conjugate gradients cannot reach falls back to the direct solver, which gives
/// the answer and says so.
#[test]
fn an_unreachable_tolerance_falls_back_to_the_direct_solver() {
    let mut body = lattice_body([4, 4, 6]).unwrap();
    body.solver.choice = SolverChoice::Direct;
    let direct = BodySolver::new(&body)
        .unwrap()
        .solve_step(&body, 1, 1)
        .unwrap();
    body.solver.choice = SolverChoice::Iterative;
    body.solver.iterative.tolerance = 1e-300;
    body.solver.iterative.max_iterations = 20;
    let mut s = BodySolver::new(&body).unwrap();
    assert_eq!(s.solver_used(), "iterative, then direct");
    let state = s.solve_step(&body, 1, 1).unwrap();
    // The same factorization (faer's parallel kernels may round the last bit differently).
    let scale = direct
        .displacements
        .iter()
        .map(|u| u.norm())
        .fold(0.0, f64::max);
    for (a, b) in state.displacements.iter().zip(&direct.displacements) {
        assert!((a - b).norm() <= 1e-12 * scale);
    }
    assert_eq!(state.linear_iterations, 20);
}

/// `solver = "iterative"` and its settings are read from the scene; an arc-length path with
/// it is refused with a reason.
#[test]
fn scene_keys_for_the_solver() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string("scenes/paper_shell.toml").unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        src.replace(
            "material = \"aluminium\"\n",
            "material = \"aluminium\"\nsolver = \"iterative\"\niterative = { tolerance = 1e-11, max_iterations = 300, warm_start = false }\n",
        ),
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    let b = &world.bodies[0];
    assert_eq!(b.solver.choice, SolverChoice::Iterative);
    assert_eq!(b.solver.iterative.tolerance, 1e-11);
    assert_eq!(b.solver.iterative.max_iterations, 300);
    assert!(!b.solver.iterative.warm_start);
    let src = std::fs::read_to_string("scenes/von_mises_truss.toml").unwrap();
    let first_body = src.find("[[bodies]]").unwrap();
    let name_end = first_body + src[first_body..].find('\n').unwrap() + 1;
    let edited = format!(
        "{}solver = \"iterative\"\n{}",
        &src[..name_end],
        &src[name_end..]
    );
    std::fs::write(
        dir.path().join("von_mises.nodes"),
        std::fs::read("scenes/von_mises.nodes").unwrap(),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("von_mises.links"),
        std::fs::read("scenes/von_mises.links").unwrap(),
    )
    .unwrap();
    let scene = dir.path().join("v.toml");
    std::fs::write(&scene, edited).unwrap();
    let message = load_scene(&scene).unwrap_err().to_string();
    assert!(message.contains("arc-length"), "{message}");
    // Where (the edited scene) and what to do instead.
    assert!(
        message.contains("v.toml") && message.contains("use solver = \"direct\" or \"auto\""),
        "{message}"
    );
}
