//! How often this platform's `sin`, `cos`, `tan` and `pow` give other
//! bits than `libm`'s (the functions wasm32's std links, through
//! compiler-builtins): what a native and a browser build would compute
//! differently where the renderer calls them (docs/performance.md, round
//! 28). Prints counts; asserts nothing.
//!
//!   cargo run --release -p lensview-core --example libm_differ

fn main() {
    let mut rng = lensview_core::sampling::Sampler::new(1, 0, 0);
    let mut next = move || rng.next_f64();
    let n = 10_000_000;
    let (mut sin, mut cos) = (0, 0);
    for _ in 0..n {
        let phi = (2.0 * next() - 1.0) * std::f64::consts::PI;
        sin += usize::from(phi.sin().to_bits() != libm::sin(phi).to_bits());
        cos += usize::from(phi.cos().to_bits() != libm::cos(phi).to_bits());
    }
    println!("sin: {sin} of {n} angles in [-pi, pi) differ; cos: {cos}");
    let quarter = std::f64::consts::FRAC_PI_4;
    let mut quarter_differ = 0;
    for _ in 0..n {
        let t = (2.0 * next() - 1.0) * quarter;
        let ours = lensview_core::math::sin_cos_quarter(t);
        quarter_differ += usize::from(ours != (libm::sin(t), libm::cos(t)));
    }
    println!("math::sin_cos_quarter against libm over [-pi/4, pi/4]: {quarter_differ} of {n} differ");
    // The camera's tan(fov/2), for fields of view 1° to 179° by 0.25°.
    let (mut tan, mut fovs) = (0, 0);
    let mut f = 1.0f64;
    while f < 179.0 {
        let a = (0.5 * f).to_radians();
        tan += usize::from(a.tan().to_bits() != libm::tan(a).to_bits());
        fovs += 1;
        f += 0.25;
    }
    println!("tan(fov/2): {tan} of {fovs} fields of view differ");
    // Phong's cos^shininess.
    let m = 1_000_000;
    let mut pow = 0;
    for i in 0..m {
        let s = [8.0, 16.0, 32.0, 48.0, 64.0, 100.0][i % 6];
        let c = next();
        pow += usize::from(c.powf(s).to_bits() != libm::pow(c, s).to_bits());
    }
    println!("pow(cos, shininess): {pow} of {m} differ");
    // What moving Phong's `pow` to libm would cost a call.
    let xs: Vec<f64> = (0..m).map(|_| next()).collect();
    let time = |f: &dyn Fn(f64) -> f64| {
        let t = std::time::Instant::now();
        let s: f64 = xs.iter().map(|&c| f(c)).sum();
        (t.elapsed().as_secs_f64() * 1e9 / m as f64, s)
    };
    let (platform, a) = time(&|c: f64| c.powf(48.0));
    let (ours, b) = time(&|c: f64| libm::pow(c, 48.0));
    println!("pow(cos, 48): platform {platform:.1} ns a call, libm {ours:.1} ns (sums {a:.3}, {b:.3})");
}
