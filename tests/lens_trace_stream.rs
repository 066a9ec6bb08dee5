//! `lens trace` writes its output while it traces (issue 19 item 6): the
//! bytes are those of the whole output printed pretty, and a refusal found
//! anywhere in the input writes nothing to stdout.

use std::process::Command;

fn cases(last_direction: &str) -> String {
    let ray = r#"{"id":0,"origin":[0.5,0,30],"direction":[0,0,-1]}"#;
    let rays = vec![ray; 2000].join(",");
    format!(
        r#"{{"cases":[{{"id":"a","lens":{{"center":[0,0,0],"axis":[0,0,1],"d":20,"R1":50,"R2":50,"n":1.5}},"rays":[{rays}]}},
           {{"id":"b","lens":{{"center":[0,0,0],"axis":[0,0,1],"d":20,"R1":50,"R2":40,"n":{{"cauchy":[1.5,0.004]}}}},"rays":[]}},
           {{"id":"c","lens":{{"center":[0,0,0],"axis":[0,0,1],"d":20,"R1":50,"R2":50,"n":1.5}},"rays":[{rays},{{"id":"last","origin":[0,0,30],"direction":{last_direction}}}]}}]}}"#
    )
}

fn trace(text: &str, name: &str) -> std::process::Output {
    let path = std::env::temp_dir().join(format!("lensview-stream-{}-{name}.json", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .arg("lens")
        .arg("trace")
        .arg(&path)
        .output()
        .unwrap();
    std::fs::remove_file(&path).unwrap();
    o
}

#[test]
fn streamed_output_is_the_whole_output_printed_pretty() {
    let text = cases("[0.01,0,-1]");
    let o = trace(&text, "good");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let input: lensview::lens_tools::TraceInput = serde_json::from_str(&text).unwrap();
    let whole = lensview::lens_tools::trace_cases(&input).unwrap();
    let printed = serde_json::to_string_pretty(&whole).unwrap() + "\n";
    assert!(
        o.stdout == printed.as_bytes(),
        "streamed output differs from the whole output"
    );
    assert_eq!(whole.cases[2].rays.len(), 2001);
    assert!(whole.cases[1].rays.is_empty());
}

#[test]
fn a_refusal_after_many_rays_writes_nothing() {
    let o = trace(&cases("[0,0,0]"), "bad");
    assert!(!o.status.success());
    assert!(
        o.stdout.is_empty(),
        "{} bytes written before the refusal",
        o.stdout.len()
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("cases[2] (id \"c\").rays[2000] (id \"last\").direction"),
        "{err}"
    );
}
