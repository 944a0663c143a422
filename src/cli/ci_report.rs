//! The reports `compare` and `regress` write for CI: one JUnit XML file
//! (through quick-junit) and one HTML page for a person, each holding every
//! case of the run. The page is self-contained: its pictures are PNGs in
//! `data:` URIs, and a small script marks the page once every picture has
//! loaded (`data-images-loaded="N/N"` on `<html>`).

use std::path::{Path, PathBuf};

use anyhow::Result;
use base64::Engine;
use quick_junit::{NonSuccessKind, Property, Report, TestCase, TestCaseStatus, TestSuite};

/// One compared image or rendered scene.
pub struct Case {
    pub name: String,
    /// Why it failed (a fail-tier threshold or the z-test), if it did.
    pub failure: Option<String>,
    /// Warn-tier thresholds that did not hold (the case still passes).
    pub warnings: Vec<String>,
    pub seconds: f64,
    /// Label and value, in the order shown.
    pub figures: Vec<(String, String)>,
    pub pictures: Vec<Picture>,
}

/// A picture of a case: its caption and its PNG.
pub struct Picture {
    pub caption: String,
    pub png: Vec<u8>,
}

/// Refuses a --junit or --html path with the wrong extension or in a missing
/// folder, before any work.
pub fn check_paths(junit: Option<&Path>, html: Option<&Path>) -> Result<()> {
    if let Some(p) = junit {
        super::check_output(p, "xml", "--junit")?;
    }
    if let Some(p) = html {
        super::check_output(p, "html", "--html")?;
    }
    Ok(())
}

/// The files asked for, as (path, bytes), to be written with the command's
/// other outputs all or nothing.
pub fn files(
    suite: &str,
    cases: &[Case],
    junit: Option<&Path>,
    html: Option<&Path>,
) -> Result<Vec<(PathBuf, Vec<u8>)>> {
    let mut out = Vec::new();
    if let Some(p) = junit {
        out.push((p.to_path_buf(), junit_xml(suite, cases)?.into_bytes()));
    }
    if let Some(p) = html {
        out.push((p.to_path_buf(), html_page(suite, cases).into_bytes()));
    }
    Ok(out)
}

/// One test suite named `suite` with a test case per case: a `<failure>`
/// when it failed; warnings as properties and in its system-out.
pub fn junit_xml(suite: &str, cases: &[Case]) -> Result<String> {
    let mut ts = TestSuite::new(suite);
    let mut total = 0.0;
    for c in cases {
        let status = match &c.failure {
            None => TestCaseStatus::success(),
            Some(message) => {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
                s.set_message(message.as_str());
                s
            }
        };
        let mut tc = TestCase::new(c.name.as_str(), status);
        tc.set_classname(suite);
        tc.set_time(std::time::Duration::from_secs_f64(c.seconds.max(0.0)));
        for (label, value) in &c.figures {
            tc.add_property(Property::new(label.as_str(), value.as_str()));
        }
        for w in &c.warnings {
            tc.add_property(Property::new("warning", w.as_str()));
        }
        if !c.warnings.is_empty() {
            tc.set_system_out(format!("warning: {}\n", c.warnings.join("\nwarning: ")));
        }
        ts.add_test_case(tc);
        total += c.seconds.max(0.0);
    }
    ts.set_time(std::time::Duration::from_secs_f64(total));
    let mut report = Report::new(format!("photonmap {suite}"));
    report.add_test_suite(ts);
    Ok(report.to_string()?)
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

const STYLE: &str = "body{font-family:sans-serif;margin:1.5em;background:#fafafa}\
section{margin-bottom:2em;padding:1em;background:#fff;border-left:6px solid #2a2}\
section.fail{border-color:#c22}section.warn{border-color:#e90}\
.row{display:flex;gap:1em;overflow-x:auto}figure{margin:0}\
img{min-width:256px;image-rendering:pixelated;border:1px solid #ccc}\
table{border-collapse:collapse}td{padding:0 1em 0 0}";

/// Sets data-images-loaded="loaded/total" on <html> once the page has
/// loaded: a picture counts when it decoded (naturalWidth > 0).
const SCRIPT: &str = "window.addEventListener('load',function(){\
var i=document.images,n=0;for(var k=0;k<i.length;k++){if(i[k].complete&&i[k].naturalWidth>0)n++;}\
document.documentElement.setAttribute('data-images-loaded',n+'/'+i.length);});";

/// The page: per case its verdict, figures, and pictures side by side.
pub fn html_page(suite: &str, cases: &[Case]) -> String {
    let failed = cases.iter().filter(|c| c.failure.is_some()).count();
    let mut s = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head><meta charset=\"utf-8\">\
<title>photonmap {suite}</title>\n<style>{STYLE}</style>\n<script>{SCRIPT}</script></head>\n<body>\n\
<h1>photonmap {suite}: {} of {} passed</h1>\n",
        cases.len() - failed,
        cases.len()
    );
    for c in cases {
        let (class, verdict) = match (&c.failure, c.warnings.is_empty()) {
            (Some(_), _) => ("fail", "FAIL"),
            (None, false) => ("warn", "pass with warnings"),
            (None, true) => ("pass", "pass"),
        };
        s += &format!(
            "<section class=\"{class}\">\n<h2>{}: {verdict}</h2>\n",
            escape(&c.name)
        );
        if let Some(f) = &c.failure {
            s += &format!("<p><b>{}</b></p>\n", escape(f));
        }
        for w in &c.warnings {
            s += &format!("<p>warning: {}</p>\n", escape(w));
        }
        s += "<table>\n";
        for (label, value) in &c.figures {
            s += &format!(
                "<tr><td>{}</td><td>{}</td></tr>\n",
                escape(label),
                escape(value)
            );
        }
        s += "</table>\n<div class=\"row\">\n";
        for p in &c.pictures {
            s += &format!(
                "<figure><img alt=\"{0}\" src=\"data:image/png;base64,{1}\"><figcaption>{0}</figcaption></figure>\n",
                escape(&p.caption),
                base64::engine::general_purpose::STANDARD.encode(&p.png)
            );
        }
        s += "</div>\n</section>\n";
    }
    s + "</body>\n</html>\n"
}
