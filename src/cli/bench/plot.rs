//! Log-log plots as SVG written by hand (plotters' text needs system fonts a
//! CI machine may lack): labelled points, joined lines, and flat levels.

/// One set of points: drawn as dots, joined when `joined`, each with its label.
struct Series {
    name: String,
    colour: String,
    points: Vec<(f64, f64, String)>,
    joined: bool,
}

pub struct LogLog {
    title: String,
    x_label: String,
    y_label: String,
    series: Vec<Series>,
    /// Horizontal dashed lines: (name, colour, y).
    levels: Vec<(String, String, f64)>,
}

impl LogLog {
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            levels: Vec::new(),
        }
    }

    /// Points joined by a line, in the order given.
    pub fn line(&mut self, name: &str, colour: &str, points: Vec<(f64, f64)>) {
        self.series.push(Series {
            name: name.into(),
            colour: colour.into(),
            points: points
                .into_iter()
                .map(|(x, y)| (x, y, String::new()))
                .collect(),
            joined: true,
        });
    }

    /// Labelled points, joined when `joined` (sorted by x first).
    pub fn points(&mut self, colour: &str, mut points: Vec<(f64, f64, String)>, joined: bool) {
        if joined {
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        self.series.push(Series {
            name: String::new(),
            colour: colour.into(),
            points,
            joined,
        });
    }

    /// A horizontal dashed line at `y`.
    pub fn level(&mut self, name: &str, colour: &str, y: f64) {
        self.levels.push((name.into(), colour.into(), y));
    }

    /// Decades spanned by the values (floored at 1e-9), at least one.
    fn decades(values: impl Iterator<Item = f64>) -> (f64, f64) {
        let logs: Vec<f64> = values.map(|v| v.max(1e-9).log10()).collect();
        let lo = logs.iter().copied().fold(f64::INFINITY, f64::min).floor();
        let hi = logs
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
            .ceil();
        match (lo.is_finite(), hi > lo) {
            (false, _) => (0.0, 1.0),
            (true, false) => (lo, lo + 1.0),
            (true, true) => (lo, hi),
        }
    }

    pub fn svg(&self) -> String {
        let (w, h, m) = (720.0, 480.0, 70.0);
        let all = || self.series.iter().flat_map(|s| s.points.iter());
        let (x0, x1) = Self::decades(all().map(|p| p.0));
        let (y0, y1) = Self::decades(all().map(|p| p.1).chain(self.levels.iter().map(|l| l.2)));
        let px = |x: f64| m + (x.max(1e-9).log10() - x0) / (x1 - x0) * (w - 2.0 * m);
        let py = |y: f64| h - m - (y.max(1e-9).log10() - y0) / (y1 - y0) * (h - 2.0 * m);
        let mut s = format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n");
        s += &format!(
            "<text x=\"{}\" y=\"22\" font-size=\"15\" text-anchor=\"middle\">{}</text>\n",
            w / 2.0,
            escape(&self.title)
        );
        s += &format!("<line x1=\"{m}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"black\"/>\n<line x1=\"{m}\" y1=\"{m}\" x2=\"{m}\" y2=\"{}\" stroke=\"black\"/>\n", h - m, w - m, h - m, h - m);
        for d in x0 as i64..=x1 as i64 {
            let x = px(10f64.powi(d as i32));
            s += &format!("<line x1=\"{x}\" y1=\"{}\" x2=\"{x}\" y2=\"{}\" stroke=\"black\"/><text x=\"{x}\" y=\"{}\" text-anchor=\"middle\">1e{d}</text>\n", h - m, h - m + 5.0, h - m + 18.0);
        }
        for d in y0 as i64..=y1 as i64 {
            let y = py(10f64.powi(d as i32));
            s += &format!("<line x1=\"{}\" y1=\"{y}\" x2=\"{m}\" y2=\"{y}\" stroke=\"black\"/><text x=\"{}\" y=\"{}\" text-anchor=\"end\">1e{d}</text>\n", m - 5.0, m - 8.0, y + 4.0);
        }
        s += &format!(
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n",
            w / 2.0,
            h - 20.0,
            escape(&self.x_label)
        );
        s += &format!("<text x=\"18\" y=\"{}\" transform=\"rotate(-90 18 {})\" text-anchor=\"middle\">{}</text>\n", h / 2.0, h / 2.0, escape(&self.y_label));
        let mut legend = Vec::new();
        for series in &self.series {
            if series.joined {
                let path: Vec<String> = series
                    .points
                    .iter()
                    .map(|p| format!("{:.1},{:.1}", px(p.0), py(p.1)))
                    .collect();
                s += &format!(
                    "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\"/>\n",
                    path.join(" "),
                    series.colour
                );
            }
            for (x, y, label) in &series.points {
                s += &format!(
                    "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\" fill=\"{}\"/><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"9\">{}</text>\n",
                    px(*x),
                    py(*y),
                    series.colour,
                    px(*x) + 6.0,
                    py(*y) - 5.0,
                    escape(label)
                );
            }
            if !series.name.is_empty() {
                legend.push((series.name.clone(), series.colour.clone(), false));
            }
        }
        for (name, colour, y) in &self.levels {
            s += &format!(
                "<line x1=\"{m}\" y1=\"{0:.1}\" x2=\"{1}\" y2=\"{0:.1}\" stroke=\"{colour}\" stroke-dasharray=\"6 4\"/>\n",
                py(*y),
                w - m
            );
            legend.push((name.clone(), colour.clone(), true));
        }
        for (i, (name, colour, dashed)) in legend.iter().enumerate() {
            let y = m + 14.0 * i as f64;
            let dash = if *dashed {
                " stroke-dasharray=\"6 4\""
            } else {
                ""
            };
            s += &format!(
                "<line x1=\"{}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"{colour}\" stroke-width=\"2\"{dash}/><text x=\"{}\" y=\"{}\">{}</text>\n",
                m + 10.0,
                m + 30.0,
                m + 35.0,
                y + 4.0,
                escape(name)
            );
        }
        s + "</svg>\n"
    }
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
