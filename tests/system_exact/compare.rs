//! The comparison of `lens trace`'s output for lens systems with the
//! reference (`tests/system_exact.rs`): the input JSON, running the binary,
//! the per-ray differences and the excuses.

use crate::reference::system::{D_LINE_UM, Status};
use crate::reference::system::{Event, SysPath, System, trace, trace_from};
use crate::reference::system_cases::Case;
use crate::reference::{DD, Real, V3};
use crate::{DIR_TOLERANCE, MARGIN_SKIP, POS_TOLERANCE, distance, max_abs, structure};
use serde_json::{Value, json};
use std::process::Command;

/// The input of `lens trace` for systems (issue #31), exactly as specified.
pub fn input_json(cases: &[Case]) -> Value {
    let cases: Vec<Value> = cases
        .iter()
        .map(|c| {
            let rays: Vec<Value> = c
                .rays
                .iter()
                .map(|r| {
                    let mut v = json!({ "id": r.id, "origin": r.origin, "direction": r.direction });
                    if let Some(l) = r.wavelength_um {
                        v["wavelength_um"] = json!(l);
                    }
                    v
                })
                .collect();
            json!({ "id": c.id, "system": c.system.to_json(), "rays": rays })
        })
        .collect();
    json!({ "cases": cases })
}

/// Runs `lensview lens trace` on `cases`, returns its parsed output.
pub fn run_lens_trace(cases: &[Case]) -> Value {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("systems.json");
    std::fs::write(&path, serde_json::to_string(&input_json(cases)).expect("JSON")).expect("written");
    let out = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .arg("lens")
        .arg("trace")
        .arg(&path)
        .output()
        .expect("lensview runs");
    assert!(
        out.status.success(),
        "`lensview lens trace` did not accept the lens-system input ({}). This is expected until the crate \
         supports systems (issue #31, docs/lens-systems.md); the reference's own checks are the \
         `reference_self_check_*` tests.\nstderr: {}",
        out.status,
        String::from_utf8_lossy(&out.stderr).trim()
    );
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("`lens trace` printed no JSON: {e}"))
}

fn triple(v: &Value) -> Option<[f64; 3]> {
    let a = v.as_array()?;
    (a.len() == 3).then_some(())?;
    Some([a[0].as_f64()?, a[1].as_f64()?, a[2].as_f64()?])
}

/// What differs between one printed ray and the reference, and the worst
/// point and direction errors as fractions of the tolerances.
#[derive(Default)]
struct Diff {
    problems: Vec<String>,
    pos: f64,
    dir: f64,
}

impl Diff {
    fn point(&mut self, what: &str, got: Option<[f64; 3]>, want: V3<DD>, tol: f64) {
        match got {
            Some(g) => {
                let r = distance(g, want) / (tol + 4.0 * f64::EPSILON * max_abs(g));
                self.pos = self.pos.max(r);
                if !(r <= 1.0) {
                    self.problems.push(format!(
                        "{what} {g:?}, reference {:?} ({r:.2e} of the tolerance)",
                        want.to_f64()
                    ));
                }
            }
            None => self.problems.push(format!("{what} missing")),
        }
    }
    fn direction(&mut self, what: &str, got: Option<[f64; 3]>, want: V3<DD>) {
        match got {
            Some(g) => {
                let r = distance(g, want) / DIR_TOLERANCE;
                self.dir = self.dir.max(r);
                if !(r <= 1.0) {
                    self.problems.push(format!(
                        "{what} {g:?}, reference {:?} ({r:.2e} of the tolerance)",
                        want.to_f64()
                    ));
                }
            }
            None => self.problems.push(format!("{what} missing")),
        }
    }
    fn same<A: PartialEq + std::fmt::Debug, B: std::fmt::Debug>(&mut self, what: &str, got: A, want: A, show: B) {
        if got != want {
            self.problems.push(format!("{what}: got {got:?}, reference {show:?}"));
        }
    }
}

fn event_diff(d: &mut Diff, i: usize, got: &Value, want: &Event<DD>, tol: f64) {
    d.same(
        &format!("event {i} surface"),
        got["surface"].as_u64(),
        Some(want.surface as u64),
        want.surface,
    );
    d.same(
        &format!("event {i} piece"),
        got["piece"].as_str(),
        Some(want.piece.name()),
        want.piece,
    );
    d.same(
        &format!("event {i} kind"),
        got["kind"].as_str(),
        Some(want.kind.name()),
        want.kind,
    );
    d.point(&format!("event {i} point"), triple(&got["point"]), want.point, tol);
    d.direction(&format!("event {i} direction"), triple(&got["direction"]), want.dir);
}

fn ray_diff(got: &Value, want: &SysPath<DD>, tol: f64) -> Diff {
    let mut d = Diff::default();
    d.same("status", got["status"].as_str(), Some(want.status.name()), want.status);
    d.same(
        "n_internal_reflections",
        got["n_internal_reflections"].as_u64(),
        Some(u64::from(want.reflections)),
        want.reflections,
    );
    let events = got["events"].as_array().map(Vec::as_slice).unwrap_or(&[]);
    d.same("number of events", events.len(), want.events.len(), want.events.len());
    if want.status != Status::Trapped {
        for (i, (g, w)) in events.iter().zip(&want.events).enumerate() {
            event_diff(&mut d, i, g, w, tol);
        }
    }
    match want.exit() {
        Some(exit) => {
            d.same(
                "exit_surface",
                got["exit_surface"].as_u64(),
                Some(exit.surface as u64),
                exit.surface,
            );
            d.point("exit_point", triple(&got["exit_point"]), exit.point, tol);
            d.direction("exit_direction", triple(&got["exit_direction"]), exit.dir);
        }
        None => d.same("exit_point printed", got.get("exit_point").is_some(), false, "absent"),
    }
    d
}

/// True when the exact path of the ray is not determined by its f64 input:
/// a nudge of one rounding at the system's scale (ε·L of the origin, ε of
/// the direction; `L = tol/POS_TOLERANCE`) changes its structure or moves a
/// point by more than a tenth of `tol` (chains of total reflections).
pub fn ill_conditioned(
    sys: &System<DD>,
    origin: [f64; 3],
    dir: [f64; 3],
    lambda: f64,
    want: &SysPath<DD>,
    tol: f64,
) -> bool {
    let e = f64::EPSILON;
    let (so, sd) = (e * tol / POS_TOLERANCE, e);
    let nudged = [[so, -so, so, sd, sd, -sd], [-so, so, so, -sd, sd, sd]];
    nudged.iter().any(|n| {
        let o = V3::<DD>::of(origin) + V3::of([n[0], n[1], n[2]]);
        let u = V3::<DD>::of(dir).normalize();
        let u = (u + V3::of([n[3], n[4], n[5]])).normalize();
        let p = trace_from(sys, o, u, lambda);
        structure(&p) != structure(want)
            || p.events.iter().zip(&want.events).any(|(a, b)| {
                (a.point - b.point).length().to_f64() > 0.1 * tol || (a.dir - b.dir).length().to_f64() > 0.1e-9
            })
    })
}

#[derive(Default)]
pub struct Stats {
    pub compared: usize,
    pub near_border: usize,
    pub ill_conditioned: usize,
    pub worst_pos: f64,
    pub worst_dir: f64,
    pub failures: Vec<String>,
}

pub fn compare_case(case: &Case, printed: &Value, stats: &mut Stats) {
    let sys = System::<DD>::new(&case.system);
    let tol = POS_TOLERANCE * case.system.length();
    let rays = printed["rays"].as_array().map(Vec::as_slice).unwrap_or(&[]);
    for ray in &case.rays {
        let lambda = ray.wavelength_um.unwrap_or(D_LINE_UM);
        let want = trace(&sys, ray.origin, ray.direction, lambda);
        let Some(got) = rays.iter().find(|r| r["id"].as_str() == Some(ray.id.as_str())) else {
            stats.failures.push(format!("{} {}: not printed", case.id, ray.id));
            continue;
        };
        stats.compared += 1;
        let d = ray_diff(got, &want, tol);
        if d.problems.is_empty() {
            stats.worst_pos = stats.worst_pos.max(d.pos);
            stats.worst_dir = stats.worst_dir.max(d.dir);
        } else if want.margin < MARGIN_SKIP {
            stats.near_border += 1;
        } else if ill_conditioned(&sys, ray.origin, ray.direction, lambda, &want, tol) {
            stats.ill_conditioned += 1;
        } else {
            stats
                .failures
                .push(format!("{} {}: {}", case.id, ray.id, d.problems.join("; ")));
        }
    }
}

/// The output `lens trace` is to print, made by the reference in `T`.
pub fn printed_by<T: Real>(cases: &[Case]) -> Value {
    let v = |x: V3<T>| json!(x.to_f64());
    let cases: Vec<Value> = cases
        .iter()
        .map(|c| {
            let sys = System::<T>::new(&c.system);
            let rays: Vec<Value> = c
                .rays
                .iter()
                .map(|r| {
                    let p = trace(&sys, r.origin, r.direction, r.wavelength_um.unwrap_or(D_LINE_UM));
                    let events: Vec<Value> = p
                        .events
                        .iter()
                        .map(|e| json!({ "surface": e.surface, "piece": e.piece.name(), "kind": e.kind.name(), "point": v(e.point), "direction": v(e.dir) }))
                        .collect();
                    let mut out = json!({ "id": r.id, "status": p.status.name(), "n_internal_reflections": p.reflections, "events": events });
                    if let Some(e) = p.exit() {
                        out["exit_point"] = v(e.point);
                        out["exit_direction"] = v(e.dir);
                        out["exit_surface"] = json!(e.surface);
                    }
                    out
                })
                .collect();
            json!({ "id": c.id, "rays": rays })
        })
        .collect();
    json!({ "cases": cases })
}
