//! `veach plot-convergence`: RMSE against time or spp, log-log, from --stats-json files.

use crate::args::PlotArgs;
use veach::Error;

pub fn run(args: &PlotArgs) -> Result<(), Error> {
    if veach::output::check_output(&args.output)? != veach::output::Format::Png {
        return Err(Error::Input(format!("{}: the plot is a .png", args.output.display())));
    }
    let mut series = Vec::new();
    for path in &args.stats {
        let fail = |m: &str| Error::Input(format!("{}: {m}", path.display()));
        let text = std::fs::read_to_string(path).map_err(|e| fail(&format!("cannot read: {e}")))?;
        let stats: serde_json::Value = serde_json::from_str(&text).map_err(|e| fail(&format!("invalid JSON: {e}")))?;
        let points = stats["convergence"]
            .as_array()
            .ok_or_else(|| fail("no \"convergence\" series (render with --reference and --stats-json)"))?;
        let key = match args.x {
            crate::args::PlotX::Seconds => "seconds",
            crate::args::PlotX::Spp => "spp",
        };
        let points: Vec<(f64, f64)> =
            points.iter().filter_map(|p| Some((p[key].as_f64()?, p["rmse"].as_f64()?))).collect();
        if points.is_empty() {
            return Err(fail("the convergence series is empty"));
        }
        let stem = path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().to_string());
        let what = [&stats["backend"], &stats["strategy"]]
            .iter()
            .filter_map(|v| v.as_str().map(str::to_string))
            .collect::<Vec<_>>()
            .join(" ");
        series.push(crate::plot_image::Series { label: format!("{stem} ({what})"), points });
    }
    let x_label = match args.x {
        crate::args::PlotX::Seconds => "RENDER TIME (S)",
        crate::args::PlotX::Spp => "SAMPLES PER PIXEL",
    };
    let img = crate::plot_image::plot_loglog(&series, x_label, "RMSE");
    veach::output::write_png(&img, &args.output)?;
    eprintln!("veach: wrote {}", args.output.display());
    Ok(())
}
