//! The computations behind `lensview lens trace` and `lensview lens info`:
//! real rays through a lens described in JSON, and a lens's paraxial data
//! with its real marginal-ray focus and axial colour; and the figures of
//! `lensview lens fan`, `spot` and `distortion` (`setup.rs`: the bench and
//! the pupil; `fan.rs`: ray fan, cardinal points and LSA; `spot.rs`: spot
//! diagram; `distortion.rs`; `sketch.rs`: the cross-section and its SVG;
//! `overlay.rs`: the optics overlay over the picture; `analysis.rs`: the
//! analysis window's figures, `chart.rs` their SVG).

pub mod analysis;
pub mod bench;
pub mod chart;
pub mod distortion;
pub mod fan;
pub mod image;
pub mod overlay;
pub mod setup;
pub mod sketch;
pub mod spot;
pub mod system_bench;
pub mod system_colour;
pub mod system_fan;
pub mod system_info;
pub mod system_spot;
pub mod system_trace;

pub use distortion::{Distortion, distortion};
pub use fan::{Fan, fan};
pub use image::ImageInfo;
pub use setup::{Setup, SetupError};
pub use spot::{SpotDiagram, spot_diagram};

use crate::geometry::{
    Lens, LensBranch, LensError, LensPath, LensSurface, LensTraceStatus, MAX_INTERNAL_REFLECTIONS, Pruning,
};
use crate::optics::{Index, ThickLens, WAVELENGTH_D_UM};
use crate::render::RGB_WAVELENGTHS_UM;
use crate::scene::file::IndexFile;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// `{ "cases": [ … ] }`. Unknown keys are ignored (files may carry notes).
#[derive(Clone, Debug, Deserialize)]
pub struct TraceInput {
    pub cases: Vec<TraceCase>,
    /// Also list each ray's weighted branches ([`BranchOutput`]): set by
    /// `lens trace --branches`, never read from the file.
    #[serde(skip)]
    pub branches: bool,
}

#[derive(Clone, Debug, Deserialize)]
pub struct TraceCase {
    #[serde(default)]
    pub id: serde_json::Value,
    /// The biconvex lens; or `system`, a lens system (one of the two).
    #[serde(default)]
    pub lens: Option<LensSpec>,
    #[serde(default)]
    pub system: Option<system_trace::SystemSpec>,
    pub rays: Vec<RaySpec>,
}

#[derive(Clone, Debug, Deserialize)]
pub struct LensSpec {
    pub center: [f64; 3],
    pub axis: [f64; 3],
    pub d: f64,
    #[serde(alias = "r1")]
    #[serde(rename = "R1")]
    pub r1: f64,
    #[serde(alias = "r2")]
    #[serde(rename = "R2")]
    pub r2: f64,
    pub n: IndexFile,
}

#[derive(Clone, Debug, Deserialize)]
pub struct RaySpec {
    #[serde(default)]
    pub id: serde_json::Value,
    pub origin: [f64; 3],
    pub direction: [f64; 3],
    #[serde(default)]
    pub wavelength_um: Option<f64>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct TraceOutput {
    pub cases: Vec<CaseOutput>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct CaseOutput {
    pub id: serde_json::Value,
    pub rays: Vec<CaseRay>,
}

/// A ray's output: through the biconvex lens or through a system.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(untagged)]
pub enum CaseRay {
    Lens(RayOutput),
    System(system_trace::SystemRayOutput),
}

impl CaseRay {
    /// The output of a ray through the biconvex lens.
    pub fn lens(&self) -> Option<&RayOutput> {
        match self {
            CaseRay::Lens(r) => Some(r),
            CaseRay::System(_) => None,
        }
    }
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct RayOutput {
    pub id: serde_json::Value,
    /// "transmitted", "miss", or "trapped" (more than
    /// [`MAX_INTERNAL_REFLECTIONS`] total internal reflections).
    pub status: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub entry_surface: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub entry_point: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub entry_direction: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exit_surface: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exit_point: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exit_direction: Option<[f64; 3]>,
    pub n_internal_reflections: u32,
    /// Index used for this ray (after the wavelength, for Cauchy glass).
    pub n: f64,
    /// With `--branches`: every ray out of the lens's Whitted tree, in the
    /// order the chain inside meets them ([`Lens::branches_inside`]),
    /// those of weight above [`BRANCH_LIST_MIN`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub branches: Option<Vec<BranchOutput>>,
    /// With `--branches`: the weight not listed (branches below
    /// [`BRANCH_LIST_MIN`], and light still inside after the most
    /// reflections); with the listed weights it sums to 1.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub branches_dropped: Option<f64>,
}

/// The weight below which `lens trace --branches` leaves a branch out.
pub const BRANCH_LIST_MIN: f64 = 1e-12;

/// One ray out of the lens ([`LensBranch`]) as `lens trace --branches`
/// prints it.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct BranchOutput {
    pub exit_surface: &'static str,
    pub exit_point: [f64; 3],
    pub exit_direction: [f64; 3],
    /// The share of the light that entered leaving along this ray.
    pub weight: f64,
    /// Reflections inside before it (total and partial).
    pub n_internal_reflections: u32,
}

/// A problem with one case or ray, named by its position and id.
#[derive(Debug, thiserror::Error)]
#[error("{place}: {message}")]
pub struct TraceError {
    pub place: String,
    pub message: String,
}

pub fn index_of(n: IndexFile) -> Index {
    match n {
        IndexFile::Constant(n) => Index::Constant(n),
        IndexFile::Cauchy([a, b]) => Index::Cauchy { a, b },
        IndexFile::Glass(g) => Index::Glass(g),
    }
}

fn lens_field(e: &LensError) -> &'static str {
    match e.field() {
        "r1" => "R1",
        "r2" => "R2",
        f => f,
    }
}

/// Traces every ray of every case.
pub fn trace_cases(input: &TraceInput) -> Result<TraceOutput, TraceError> {
    let mut cases = Vec::with_capacity(input.cases.len());
    for (ci, case) in input.cases.iter().enumerate() {
        if case.system.is_some() {
            let sys = system_trace::case_system(ci, case)?;
            let rays = (case.rays.iter().enumerate())
                .map(|(ri, r)| system_trace::trace_ray(&sys, ci, case, ri, r).map(CaseRay::System))
                .collect::<Result<_, _>>()?;
            cases.push(CaseOutput {
                id: case.id.clone(),
                rays,
            });
            continue;
        }
        let lens = case_lens(ci, case)?;
        let rays = (case.rays.iter().enumerate())
            .map(|(ri, r)| trace_ray(&lens, ci, case, ri, r, input.branches).map(CaseRay::Lens))
            .collect::<Result<_, _>>()?;
        cases.push(CaseOutput {
            id: case.id.clone(),
            rays,
        });
    }
    Ok(TraceOutput { cases })
}

/// Checks every case's lens and every ray, tracing nothing: the first
/// problem that [`trace_cases`] would meet, or none.
pub fn check_cases(input: &TraceInput) -> Result<(), TraceError> {
    for (ci, case) in input.cases.iter().enumerate() {
        if case.system.is_some() {
            let sys = system_trace::case_system(ci, case)?;
            for (ri, r) in case.rays.iter().enumerate() {
                system_trace::check_ray(&sys, ci, case, ri, r)?;
            }
            continue;
        }
        let lens = case_lens(ci, case)?;
        let index = lens.index;
        for (ri, r) in case.rays.iter().enumerate() {
            ray_index(ci, case, ri, r, index)?;
        }
    }
    Ok(())
}

/// Writes what [`trace_cases`] returns as pretty JSON, byte for byte what
/// `serde_json::to_writer_pretty` writes for it, but tracing each ray as
/// it is written, so that memory does not grow with the number of rays.
/// Call [`check_cases`] first: a problem found here stops the output
/// half-way (as a `serde_json` error naming it).
pub fn write_trace_json(input: &TraceInput, out: impl std::io::Write) -> serde_json::Result<()> {
    serde_json::to_writer_pretty(out, &Streamed(input))
}

/// [`TraceOutput`] of an input, traced while serialised.
struct Streamed<'a>(&'a TraceInput);
/// [`CaseOutput`] of one case, traced while serialised.
struct StreamedCase<'a>(usize, &'a TraceCase, bool);
/// [`CaseOutput::rays`] of one case, traced while serialised.
struct StreamedRays<'a>(usize, &'a TraceCase, bool);

impl Serialize for Streamed<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let cases = self.0.cases.iter().enumerate();
        let mut st = s.serialize_struct("TraceOutput", 1)?;
        st.serialize_field(
            "cases",
            &CollectSeq(cases.map(|(ci, c)| StreamedCase(ci, c, self.0.branches))),
        )?;
        st.end()
    }
}

impl Serialize for StreamedCase<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("CaseOutput", 2)?;
        st.serialize_field("id", &self.1.id)?;
        st.serialize_field("rays", &StreamedRays(self.0, self.1, self.2))?;
        st.end()
    }
}

impl Serialize for StreamedRays<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{Error, SerializeSeq};
        let (ci, case) = (self.0, self.1);
        let mut seq = s.serialize_seq(Some(case.rays.len()))?;
        if case.system.is_some() {
            let sys = system_trace::case_system(ci, case).map_err(S::Error::custom)?;
            for (ri, r) in case.rays.iter().enumerate() {
                let out = system_trace::trace_ray(&sys, ci, case, ri, r).map_err(S::Error::custom)?;
                seq.serialize_element(&out)?;
            }
            return seq.end();
        }
        let lens = case_lens(ci, case).map_err(S::Error::custom)?;
        for (ri, r) in case.rays.iter().enumerate() {
            seq.serialize_element(&trace_ray(&lens, ci, case, ri, r, self.2).map_err(S::Error::custom)?)?;
        }
        seq.end()
    }
}

/// A sequence serialised from an iterator of exact length, as a `Vec` is.
struct CollectSeq<I>(I);

impl<I: Iterator<Item = T> + ExactSizeIterator + Clone, T: Serialize> Serialize for CollectSeq<I> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.0.clone())
    }
}

/// `cases[0] (id …)`: where a problem with a case is.
pub(crate) fn case_place(ci: usize, case: &TraceCase) -> String {
    format!("cases[{ci}] (id {})", case.id)
}

/// The lens of case `ci`, or what is wrong with it.
fn case_lens(ci: usize, case: &TraceCase) -> Result<Lens, TraceError> {
    let Some(l) = &case.lens else {
        return Err(TraceError {
            place: case_place(ci, case),
            message: "needs `lens` (the biconvex lens) or `system` (a lens system)".into(),
        });
    };
    Lens::new(
        DVec3::from(l.center),
        DVec3::from(l.axis),
        l.d,
        l.r1,
        l.r2,
        index_of(l.n),
    )
    .map_err(|e| TraceError {
        place: format!("{}.lens.{}", case_place(ci, case), lens_field(&e)),
        message: e.to_string(),
    })
}

/// The index ray `ri` of case `ci` sees, after its origin, direction and
/// wavelength are checked.
fn ray_index(ci: usize, case: &TraceCase, ri: usize, r: &RaySpec, index: Index) -> Result<f64, TraceError> {
    let rplace = || format!("{}.rays[{ri}] (id {})", case_place(ci, case), r.id);
    let origin = DVec3::from(r.origin);
    let dir = DVec3::from(r.direction);
    if !origin.is_finite() {
        return Err(TraceError {
            place: rplace() + ".origin",
            message: "must be finite".into(),
        });
    }
    if !(dir.is_finite() && dir.length() > 0.0) {
        return Err(TraceError {
            place: rplace() + ".direction",
            message: "must be a finite non-zero vector".into(),
        });
    }
    let lambda = r.wavelength_um.unwrap_or(WAVELENGTH_D_UM);
    if !(lambda > 0.0 && lambda.is_finite()) {
        return Err(TraceError {
            place: rplace() + ".wavelength_um",
            message: format!("{lambda} must be positive"),
        });
    }
    let n = index.at(lambda);
    if !(n >= 1.0 && n.is_finite()) {
        return Err(TraceError {
            place: rplace() + ".wavelength_um",
            message: format!("index {n} at {lambda} µm is below 1"),
        });
    }
    Ok(n)
}

/// Ray `ri` of case `ci` traced through `lens` (the case's lens), with its
/// weighted branches when `branches`.
fn trace_ray(
    lens: &Lens,
    ci: usize,
    case: &TraceCase,
    ri: usize,
    r: &RaySpec,
    branches: bool,
) -> Result<RayOutput, TraceError> {
    let n = ray_index(ci, case, ri, r, lens.index)?;
    let p = lens.trace(DVec3::from(r.origin), DVec3::from(r.direction), n);
    let side = |x: Option<(LensSurface, DVec3, DVec3)>| x.map(|(s, p, d)| (s.name(), p.to_array(), d.to_array()));
    let entry = side(p.entry);
    let exit = side(p.exit);
    Ok(RayOutput {
        id: r.id.clone(),
        status: match p.status {
            LensTraceStatus::Transmitted => "transmitted",
            LensTraceStatus::Miss => "miss",
            LensTraceStatus::Trapped => "trapped",
        },
        entry_surface: entry.map(|e| e.0),
        entry_point: entry.map(|e| e.1),
        entry_direction: entry.map(|e| e.2),
        exit_surface: exit.map(|e| e.0),
        exit_point: exit.map(|e| e.1),
        exit_direction: exit.map(|e| e.2),
        n_internal_reflections: p.internal_reflections,
        n,
        branches: None,
        branches_dropped: None,
    }
    .with_branches(branches.then(|| ray_branches(lens, &p, r, n))))
}

impl RayOutput {
    fn with_branches(mut self, b: Option<(Vec<BranchOutput>, f64)>) -> Self {
        if let Some((list, dropped)) = b {
            self.branches = Some(list);
            self.branches_dropped = Some(dropped);
        }
        self
    }
}

/// The branches of the ray `r` (index `n`) whose principal path is `p`:
/// from its entry, or from its origin when it starts inside; none for a miss.
fn ray_branches(lens: &Lens, p: &LensPath, r: &RaySpec, n: f64) -> (Vec<BranchOutput>, f64) {
    let start = match p.entry {
        Some((_, x, inside)) => Some((x, inside)),
        None if p.status != LensTraceStatus::Miss => Some((
            DVec3::from(r.origin),
            crate::math::rescale_pow2(DVec3::from(r.direction)).normalize(),
        )),
        None => None,
    };
    let Some((x, u)) = start else {
        return (Vec::new(), 1.0);
    };
    let prune = Pruning {
        min: BRANCH_LIST_MIN,
        ..Pruning::NONE
    };
    let mut list = Vec::new();
    let dropped = lens.branches_inside(x, u, n, &prune, &mut |b: LensBranch| {
        list.push(BranchOutput {
            exit_surface: b.face.name(),
            exit_point: b.point.to_array(),
            exit_direction: b.dir.to_array(),
            weight: b.weight,
            n_internal_reflections: b.reflections,
        })
    });
    (list, dropped)
}

/// `lens info`: paraxial data, the real marginal-ray focus, axial colour.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct LensInfo {
    pub d: f64,
    pub r1: f64,
    pub r2: f64,
    pub wavelength_um: f64,
    pub n: f64,
    pub thickness: f64,
    pub sag1: f64,
    pub sag2: f64,
    /// Effective focal length; `None` (JSON `null`) when the lens has no
    /// power, as are the four below: see [`LensInfo::no_power`].
    pub efl: Option<f64>,
    /// Back focal distance, from the vertex of S2 (light enters through S1).
    pub bfd: Option<f64>,
    /// Front focal distance, before the vertex of S1.
    pub ffd: Option<f64>,
    /// Front principal plane H, from V1, positive in the direction of travel.
    pub principal_front_from_v1: Option<f64>,
    /// Rear principal plane H', from V2, positive in the direction of travel.
    pub principal_rear_from_v2: Option<f64>,
    /// Why the focal data are `null`: at n = 1 the lens bends no ray and its
    /// focal lengths are infinite (JSON has no ∞). Absent for a lens with power.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub no_power: Option<&'static str>,
    /// Height of the real marginal ray, 0.9·d/2.
    pub marginal_height: f64,
    /// Where the real marginal ray (or its backward extension) crosses the
    /// axis, from V2 (`null` if it does not leave through S2).
    pub marginal_focus_from_v2: Option<f64>,
    /// Longitudinal spherical aberration: marginal focus − BFD.
    pub spherical_aberration: Option<f64>,
    /// For Cauchy glass: back focal distance at F (486.1 nm) minus at C
    /// (656.3 nm); negative when blue focuses closer, as in every simple lens.
    pub axial_colour: Option<f64>,
    pub max_internal_reflections: u32,
    /// For a catalogue glass: its name, `nd` and Abbe number `vd` (from
    /// its Sellmeier formula at 587.56, 486.13 and 656.27 nm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub glass: Option<GlassInfo>,
    /// With an object distance ([`LensInfo::with_object`]): the paraxial
    /// image, real or virtual.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub image: Option<ImageInfo>,
}

/// [`LensInfo::glass`].
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct GlassInfo {
    pub name: &'static str,
    pub nd: f64,
    pub abbe: f64,
}

/// [`LensInfo::no_power`]'s reason.
pub const NO_POWER: &str =
    "n = 1: the lens bends no ray; its focal lengths are infinite and it has no principal planes";

/// The real ray parallel to the axis at height `h` through a lens on the z
/// axis: where it crosses the axis, measured from V2 along the direction of
/// travel.
pub fn real_focus(lens: &Lens, h: f64, n: f64) -> Option<f64> {
    let start = lens.vertex(LensSurface::S1) + lens.axis * lens.d + DVec3::X * h;
    // For a strongly aberrated lens (a ball lens at 0.9 of its aperture)
    // the crossing lies before V2.
    setup::exit_axis_crossing(lens, start, -lens.axis, n)
}

pub fn lens_info(d: f64, r1: f64, r2: f64, index: Index, wavelength_um: f64) -> Result<LensInfo, LensError> {
    let lens = Lens::new(DVec3::ZERO, DVec3::Z, d, r1, r2, index)?;
    let n = index.at(wavelength_um);
    if !(n >= 1.0 && n.is_finite()) {
        return Err(LensError::Index(n));
    }
    let px = ThickLens::new(d, r1, r2, n);
    let h = 0.9 * 0.5 * d;
    // Without power a ray leaves parallel: it has no focus.
    let power = px.has_power();
    let marginal = real_focus(&lens, h, n).filter(|_| power);
    let focal = |x: f64| Some(x).filter(|_| power);
    let axial_colour = index.is_dispersive().then(|| {
        let bfd = |l: f64| ThickLens::new(d, r1, r2, index.at(l)).bfd;
        bfd(RGB_WAVELENGTHS_UM[2]) - bfd(RGB_WAVELENGTHS_UM[0])
    });
    Ok(LensInfo {
        d,
        r1,
        r2,
        wavelength_um,
        n,
        thickness: px.thickness,
        sag1: px.sag1,
        sag2: px.sag2,
        efl: focal(px.efl),
        bfd: focal(px.bfd),
        ffd: focal(px.ffd),
        principal_front_from_v1: focal(px.h1),
        principal_rear_from_v2: focal(px.h2),
        no_power: (!power).then_some(NO_POWER),
        marginal_height: h,
        marginal_focus_from_v2: marginal,
        spherical_aberration: marginal.map(|m| m - px.bfd),
        axial_colour,
        max_internal_reflections: MAX_INTERNAL_REFLECTIONS,
        glass: match index {
            Index::Glass(g) => Some(GlassInfo {
                name: g.name,
                nd: g.nd(),
                abbe: g.abbe(),
            }),
            _ => None,
        },
        image: None,
    })
}

/// A number in `lens info`'s table: rounded to 9 decimals and
/// right-aligned, so the decimal points line up (scientific notation for
/// magnitudes outside 1e-4..1e6); with `exact` (`{:#}`, `lens info
/// --exact`) the shortest text that reads back to the same `f64`, every
/// digit meant (the JSON keeps every digit too).
pub fn table_number(x: f64, exact: bool) -> String {
    if exact {
        return format!("{x:<24}");
    }
    let a = x.abs();
    let s = if x == 0.0 || (1e-4..1e6).contains(&a) || !x.is_finite() {
        format!("{x:.9}")
    } else {
        format!("{x:.9e}")
    };
    format!("{s:>18}")
}

/// One row of `lens info`'s table: the label in its column, the values,
/// and a note.
pub(crate) fn table_row(f: &mut std::fmt::Formatter, label: &str, values: &[f64], note: &str) -> std::fmt::Result {
    let v: Vec<String> = values.iter().map(|&x| table_number(x, f.alternate())).collect();
    let note = if note.is_empty() {
        String::new()
    } else {
        format!("   {note}")
    };
    writeln!(f, "  {label:<30}{}{note}", v.join("  "))
}

impl std::fmt::Display for LensInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        writeln!(
            f,
            "lens d = {}, R1 = {}, R2 = {}, n = {} at λ = {} µm",
            self.d, self.r1, self.r2, self.n, self.wavelength_um
        )?;
        if let Some(gl) = &self.glass {
            writeln!(
                f,
                "  glass {}: nd = {:.5}, Abbe number vd = {:.2}",
                gl.name, gl.nd, gl.abbe
            )?;
        }
        table_row(f, "centre thickness", &[self.thickness], "")?;
        table_row(f, "sagitta S1, S2", &[self.sag1, self.sag2], "")?;
        if let Some(why) = self.no_power {
            writeln!(f, "  no power ({why})")?;
            for label in ["effective focal length", "back focal distance", "front focal distance"] {
                writeln!(f, "  {label:<30}{:>18}", "∞")?;
            }
            writeln!(f, "  {:<30}{:>18}", "principal planes H, H′", "none")?;
            writeln!(
                f,
                "  real ray at 0.9·d/2 = {} leaves parallel: no focus",
                self.marginal_height
            )?;
            return Ok(());
        }
        let g = |x: Option<f64>| [x.unwrap_or(f64::NAN)];
        table_row(f, "effective focal length", &g(self.efl), "")?;
        table_row(f, "back focal distance", &g(self.bfd), "(from V2)")?;
        table_row(f, "front focal distance", &g(self.ffd), "(before V1)")?;
        let along = "+ along the light";
        table_row(
            f,
            "principal plane H",
            &g(self.principal_front_from_v1),
            &format!("(from V1, {along})"),
        )?;
        table_row(
            f,
            "principal plane H′",
            &g(self.principal_rear_from_v2),
            &format!("(from V2, {along})"),
        )?;
        match (self.marginal_focus_from_v2, self.spherical_aberration) {
            (Some(m), Some(sa)) => {
                let h = self.marginal_height;
                table_row(f, "real focus of ray at 0.9·d/2", &[m], &format!("(from V2; h = {h})"))?;
                table_row(f, "longitudinal sph. aberration", &[sa], "(real − paraxial)")?;
            }
            _ => writeln!(
                f,
                "  real ray at 0.9·d/2 = {} does not leave through S2",
                self.marginal_height
            )?,
        }
        if let Some(c) = self.axial_colour {
            table_row(f, "axial colour BFD(F) − BFD(C)", &[c], "(486.1 nm − 656.3 nm)")?;
        }
        if let Some(im) = &self.image {
            image::write_image(f, im)?;
        }
        Ok(())
    }
}

/// The fuzz oracle for `lens trace` input (fuzz/fuzz_targets/lens_trace.rs,
/// replayed by tests/fuzz_corpus.rs): reads `bytes` as the cases file and
/// panics if [`check_cases`] and [`trace_cases`] disagree about a refusal,
/// if a refusal is not one line free of control characters, or if the
/// streamed output ([`write_trace_json`]) is not, byte for byte, the whole
/// output printed pretty. Panicking is its purpose; nothing else calls it.
#[doc(hidden)]
pub fn check_trace_bytes(bytes: &[u8]) {
    let Ok(input) = serde_json::from_slice::<TraceInput>(bytes) else {
        return;
    };
    let whole = trace_cases(&input);
    match check_cases(&input) {
        Err(e) => {
            let shown = e.to_string();
            assert!(!shown.chars().any(char::is_control), "{shown:?}");
            assert_eq!(whole.err().map(|w| w.to_string()), Some(shown));
        }
        Ok(()) => {
            let whole = whole.unwrap_or_else(|e| panic!("checked, then refused: {e}"));
            let mut streamed = Vec::new();
            write_trace_json(&input, &mut streamed).unwrap_or_else(|e| panic!("cannot stream: {e}"));
            let printed = serde_json::to_string_pretty(&whole).unwrap_or_else(|e| panic!("cannot print: {e}"));
            assert!(
                streamed == printed.as_bytes(),
                "streamed:\n{}\nwhole:\n{printed}",
                String::from_utf8_lossy(&streamed)
            );
        }
    }
}
