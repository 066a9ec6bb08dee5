//! A small catalogue of optical glasses: Sellmeier dispersion in SCHOTT's
//! form, `n²(λ) = 1 + Σᵢ Bᵢλ²/(λ² − Cᵢ)` with λ in micrometres, and the
//! catalogue's own `nd` and Abbe number `vd` for checking.
//!
//! Sources: the SCHOTT glasses take their coefficients, `nd` and `vd` from
//! the SCHOTT Zemax catalogue 2017-01-20b and its data sheets (as carried by
//! the refractiveindex.info database, `glass/schott/*.yml`, CC0). Fused
//! silica is Malitson's fit (J. Opt. Soc. Am. 55, 1205, 1965), whose
//! published resonances are wavelengths (µm), squared here; its `nd` is
//! Malitson's tabulated 1.45846 and its `vd` 67.8 (Corning HPFS 7980 and
//! Heraeus Suprasil data sheets).
//!
//! Names are matched without regard to case, `-`, `_` or spaces, so
//! `N-BK7`, `n-bk7` and `NBK7` name the same glass; `BK7` (the old lead-era
//! melt) is *not* `N-BK7` and is refused.

/// Fraunhofer/helium lines of SCHOTT's `nd`, `vd` (µm).
pub const D_UM: f64 = 0.587_561_8;
pub const F_UM: f64 = 0.486_132_7;
pub const C_UM: f64 = 0.656_272_5;

/// One glass: SCHOTT-form Sellmeier coefficients (`c` in µm²) and the
/// catalogue's `nd` and `vd` (published values, not computed ones).
#[derive(Debug, PartialEq)]
pub struct Glass {
    pub name: &'static str,
    b: [f64; 3],
    c: [f64; 3],
    nd: f64,
    vd: f64,
    /// Further names the glass answers to (normalised like `name`).
    aliases: &'static [&'static str],
}

impl Glass {
    /// The index at wavelength `lambda_um` (µm) from the Sellmeier formula.
    pub fn n(&self, lambda_um: f64) -> f64 {
        let l2 = lambda_um * lambda_um;
        let mut n2 = 1.0;
        for (b, c) in self.b.iter().zip(self.c) {
            n2 += b * l2 / (l2 - c);
        }
        n2.sqrt()
    }

    /// The index at the d line, from the formula.
    pub fn nd(&self) -> f64 {
        self.n(D_UM)
    }

    /// The Abbe number `(nd − 1)/(nF − nC)`, from the formula.
    pub fn abbe(&self) -> f64 {
        (self.nd() - 1.0) / (self.n(F_UM) - self.n(C_UM))
    }

    /// The catalogue's published `nd`.
    pub fn catalogue_nd(&self) -> f64 {
        self.nd
    }

    /// The catalogue's published Abbe number `vd`.
    pub fn catalogue_vd(&self) -> f64 {
        self.vd
    }
}

const fn schott(name: &'static str, b: [f64; 3], c: [f64; 3], nd: f64, vd: f64) -> Glass {
    Glass {
        name,
        b,
        c,
        nd,
        vd,
        aliases: &[],
    }
}

/// Every glass known by name.
pub static CATALOGUE: &[Glass] = &[
    schott(
        "N-BK7",
        [1.03961212, 0.231792344, 1.01046945],
        [0.00600069867, 0.0200179144, 103.560653],
        1.51680,
        64.17,
    ),
    schott(
        "N-BAK4",
        [1.28834642, 0.132817724, 0.945395373],
        [0.00779980626, 0.0315631177, 105.965875],
        1.56883,
        55.98,
    ),
    schott(
        "N-SK16",
        [1.34317774, 0.241144399, 0.994317969],
        [0.00704687339, 0.0229005, 92.7508526],
        1.62041,
        60.32,
    ),
    schott(
        "N-SSK8",
        [1.44857867, 0.117965926, 1.06937528],
        [0.00869310149, 0.0421566593, 111.300666],
        1.61773,
        49.83,
    ),
    schott(
        "N-LAK9",
        [1.46231905, 0.344399589, 1.15508372],
        [0.00724270156, 0.0243353131, 85.4686868],
        1.69100,
        54.71,
    ),
    schott(
        "N-LAK22",
        [1.14229781, 0.535138441, 1.04088385],
        [0.00585778594, 0.0198546147, 100.834017],
        1.65113,
        55.89,
    ),
    schott(
        "N-BAF10",
        [1.5851495, 0.143559385, 1.08521269],
        [0.00926681282, 0.0424489805, 105.613573],
        1.67003,
        47.11,
    ),
    schott(
        "F2",
        [1.34533359, 0.209073176, 0.937357162],
        [0.00997743871, 0.0470450767, 111.886764],
        1.62004,
        36.37,
    ),
    schott(
        "N-F2",
        [1.39757037, 0.159201403, 1.2686543],
        [0.00995906143, 0.0546931752, 119.248346],
        1.62005,
        36.43,
    ),
    schott(
        "SF2",
        [1.40301821, 0.231767504, 0.939056586],
        [0.0105795466, 0.0493226978, 112.405955],
        1.64769,
        33.85,
    ),
    schott(
        "SF5",
        [1.46141885, 0.247713019, 0.949995832],
        [0.0111826126, 0.0508594669, 112.041888],
        1.67270,
        32.21,
    ),
    schott(
        "N-SF5",
        [1.52481889, 0.187085527, 1.42729015],
        [0.011254756, 0.0588995392, 129.141675],
        1.67271,
        32.25,
    ),
    schott(
        "SF10",
        [1.61625977, 0.259229334, 1.07762317],
        [0.0127534559, 0.0581983954, 116.60768],
        1.72825,
        28.41,
    ),
    schott(
        "N-SF11",
        [1.73759695, 0.313747346, 1.89878101],
        [0.013188707, 0.0623068142, 155.23629],
        1.78472,
        25.68,
    ),
    schott(
        "N-SF6",
        [1.77931763, 0.338149866, 2.08734474],
        [0.0133714182, 0.0617533621, 174.01759],
        1.80518,
        25.36,
    ),
    Glass {
        name: "F_SILICA",
        b: [0.6961663, 0.4079426, 0.8974794],
        c: [0.0684043 * 0.0684043, 0.1162414 * 0.1162414, 9.896161 * 9.896161],
        nd: 1.45846,
        vd: 67.8,
        aliases: &["SILICA", "FUSEDSILICA"],
    },
];

/// `name` upper-cased, without `-`, `_` and spaces.
fn normalise(name: &str) -> String {
    name.chars()
        .filter(|c| !matches!(c, '-' | '_' | ' '))
        .flat_map(char::to_uppercase)
        .collect()
}

/// The glass called `name` (case, `-`, `_` and spaces ignored).
pub fn lookup(name: &str) -> Option<&'static Glass> {
    let key = normalise(name);
    if key.is_empty() {
        return None;
    }
    CATALOGUE
        .iter()
        .find(|g| normalise(g.name) == key || g.aliases.iter().any(|a| normalise(a) == key))
}

/// The catalogue's names, comma separated (for error messages).
pub fn names() -> String {
    CATALOGUE.iter().map(|g| g.name).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_glass_matches_its_published_nd_and_abbe_number() {
        for g in CATALOGUE {
            let (nd, vd) = (g.nd(), g.abbe());
            println!(
                "{:<9} nd {nd:.6} (catalogue {:.5}, Δ {:+.1e})  vd {vd:.3} (catalogue {:.2}, Δ {:+.3})",
                g.name,
                g.nd,
                nd - g.nd,
                g.vd,
                vd - g.vd
            );
            assert!((nd - g.nd).abs() <= 2e-5, "{}: nd {nd:.6} against {}", g.name, g.nd);
            assert!((vd - g.vd).abs() <= 0.05, "{}: vd {vd:.3} against {}", g.name, g.vd);
        }
    }

    #[test]
    fn the_required_glasses_are_there_and_names_are_unique() {
        for name in [
            "N-BK7", "N-SF5", "N-SF11", "N-SK16", "F2", "N-LAK22", "N-BAF10", "F_SILICA",
        ] {
            assert_eq!(lookup(name).map(|g| g.name), Some(name));
        }
        for (i, a) in CATALOGUE.iter().enumerate() {
            for b in &CATALOGUE[i + 1..] {
                assert_ne!(normalise(a.name), normalise(b.name));
            }
        }
    }

    #[test]
    fn lookup_ignores_case_and_separators_but_not_the_n_prefix() {
        let bk7 = lookup("N-BK7").unwrap();
        for alias in ["n-bk7", "NBK7", "n_bk7", " N-BK7 "] {
            assert!(std::ptr::eq(lookup(alias).unwrap(), bk7), "{alias}");
        }
        assert!(lookup("BK7").is_none());
        assert_eq!(lookup("f2").unwrap().name, "F2");
        assert_eq!(lookup("nf2").unwrap().name, "N-F2");
        assert_eq!(lookup("fused silica").unwrap().name, "F_SILICA");
        assert!(lookup("").is_none() && lookup("--").is_none() && lookup("XYZ").is_none());
    }

    #[test]
    fn dispersion_is_normal_in_the_visible() {
        for g in CATALOGUE {
            let (blue, red) = (g.n(0.40), g.n(0.70));
            assert!(blue > g.nd() && g.nd() > red && red > 1.0, "{}", g.name);
        }
    }
}
