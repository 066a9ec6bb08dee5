use super::*;
use crate::geometry::{LensSystem, SurfaceSpec};
use crate::optics::{Index, WAVELENGTH_D_UM};
use glam::DVec3;

const AIR: Index = Index::Constant(1.0);

fn surface(radius: f64, thickness: f64, n: Index, semi_aperture: f64, stop: bool) -> SurfaceSpec {
    SurfaceSpec {
        radius,
        thickness,
        n,
        semi_aperture,
        stop,
    }
}

/// A stop `gap` before a biconvex singlet (R1 = 50, R2 = −50, t = 6) of
/// glass `n`, every length times `scale`.
fn singlet(n: Index, gap: f64, scale: f64) -> LensSystem {
    let s = vec![
        surface(0.0, gap * scale, AIR, 3.0 * scale, true),
        surface(50.0 * scale, 6.0 * scale, n, 12.0 * scale, false),
        surface(-50.0 * scale, 0.0, AIR, 12.0 * scale, false),
    ];
    LensSystem::new(DVec3::ZERO, DVec3::Z, s).unwrap()
}

fn bk7() -> Index {
    Index::Glass(crate::glass::lookup("N-BK7").unwrap())
}

/// (field °, lateral colour) at max·k/steps, k = 1..=steps, from
/// `system_distortion`.
fn colour(sys: LensSystem, max_field_deg: f64, steps: u32) -> Vec<(f64, Option<f64>)> {
    let b = SystemBench::new(sys, None, 0.0).unwrap();
    let d = super::super::system_spot::system_distortion(&b, max_field_deg, steps).unwrap();
    d.points
        .iter()
        .map(|p| (p.field_deg, p.colour.lateral_colour))
        .collect()
}

#[test]
fn glass_without_dispersion_has_none() {
    let c = colour(singlet(Index::Constant(1.5168), 10.0, 1.0), 10.0, 5);
    assert_eq!(c.len(), 5);
    for p in &c {
        assert_eq!(p.1, Some(0.0), "{p:?}");
    }
}

#[test]
fn none_on_the_axis_and_odd_in_the_field() {
    let sys = singlet(bk7(), 10.0, 1.0);
    let plane_z = sys.length() + sys.paraxial(WAVELENGTH_D_UM).bfd;
    let at = |field: f64| {
        let b = SystemBench::new(sys.clone(), None, field).unwrap();
        lateral_colour_at(&b, plane_z).lateral_colour.unwrap()
    };
    assert_eq!(at(0.0), 0.0);
    let (plus, minus) = (at(4.0), at(-4.0));
    assert!(
        plus != 0.0 && (plus + minus).abs() <= 1e-12 * plus.abs(),
        "{plus} {minus}"
    );
}

#[test]
fn the_usable_curve_starts_on_the_axis_and_stops_at_the_first_lost_ray() {
    let pts = [(1.0, Some(0.1)), (2.0, Some(0.2)), (3.0, None), (4.0, Some(0.4))];
    assert_eq!(usable_curve(pts), vec![[0.0, 0.0], [1.0, 0.1], [2.0, 0.2]]);
    assert_eq!(usable_curve([(1.0, None)]), vec![[0.0, 0.0]]);
}

/// In the small-field limit the real chief rays give the paraxial chief
/// ray's heights at F and C (a y–nu trace written here: stop, gap, two
/// refractions, the d line's back focal distance), and the lateral colour
/// scales with the system.
#[test]
fn small_fields_give_the_paraxial_lateral_colour_and_it_scales() {
    let (gap, t, c1, c2) = (10.0, 6.0, 1.0 / 50.0, -1.0 / 50.0);
    let sys = singlet(bk7(), gap, 1.0);
    let bfd = sys.paraxial(WAVELENGTH_D_UM).bfd;
    let a = 0.01_f64;
    let paraxial_height = |lambda: f64| {
        let n = bk7().at(lambda);
        let u0 = -a.to_radians().tan();
        let y1 = gap * u0;
        let u1 = (u0 - y1 * (n - 1.0) * c1) / n;
        let y2 = y1 + t * u1;
        let u2 = n * u1 - y2 * (1.0 - n) * c2;
        y2 + bfd * u2
    };
    let want = paraxial_height(SPOT_WAVELENGTHS_UM[2].1) - paraxial_height(SPOT_WAVELENGTHS_UM[0].1);
    let got = colour(sys, a, 1)[0].1.unwrap();
    eprintln!("lateral colour at {a}°: real {got:e}, paraxial {want:e}");
    assert!(want.abs() > 1e-7, "{want}");
    assert!((got - want).abs() < 1e-6 * want.abs(), "{got} {want}");
    // Ten times the system: ten times the lateral colour at each field.
    let (one, ten) = (
        colour(singlet(bk7(), gap, 1.0), 10.0, 2),
        colour(singlet(bk7(), gap, 10.0), 10.0, 2),
    );
    for (p, q) in one.iter().zip(&ten) {
        let (l1, l10) = (p.1.unwrap(), q.1.unwrap());
        assert!((l10 - 10.0 * l1).abs() <= 1e-9 * l10.abs().max(1e-12), "{l1} {l10}");
    }
}

/// A stop at the glass nearly cancels it: the chief ray passes close to
/// the lens's principal points; a stop far before it does not.
#[test]
fn a_stop_away_from_the_lens_gives_more() {
    let near = colour(singlet(bk7(), 0.5, 1.0), 10.0, 1)[0].1.unwrap();
    let far = colour(singlet(bk7(), 20.0, 1.0), 10.0, 1)[0].1.unwrap();
    eprintln!("lateral colour at 10°: stop 0.5 before the lens {near:e}, 20 before {far:e}");
    assert!(far.abs() > 5.0 * near.abs(), "{near} {far}");
}
