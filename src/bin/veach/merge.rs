//! `veach merge`: farm parts (disjoint sample ranges or tiles) into one image, exactly.

use crate::args::MergeArgs;
use veach::Error;

pub fn run(args: &MergeArgs) -> Result<(), Error> {
    veach::output::check_output(&args.output)?;
    let mut parts = Vec::new();
    for path in &args.parts {
        let (film, job) = veach::output::read_film(path)?;
        parts.push(veach::Part { film, job, path: path.clone() });
    }
    let (merged, job) = veach::merge(&parts)?;
    veach::output::write(&merged, &args.output, args.exposure, Some(&job))?;
    eprintln!("veach: merged {} parts into {}", parts.len(), args.output.display());
    Ok(())
}
