//! `varspec integrands`: the reference integrands — their names and what
//! they are, or with `--list` every parameter with its default too.

use varspec::integrands::INTEGRANDS;

#[derive(clap::Args)]
pub struct Args {
    /// List every integrand with its parameters, defaults and meanings.
    #[arg(long)]
    list: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let mut out = String::new();
    for i in INTEGRANDS {
        if a.list {
            out += &format!("{} ({}D)\n    {}\n", i.name, i.dim, i.summary);
            // One column for the meanings, whatever the keys' lengths.
            let width = i
                .params
                .iter()
                .map(|(key, default, _)| key.chars().count() + 1 + default.chars().count())
                .max()
                .unwrap_or(0);
            for (key, default, help) in i.params {
                let assignment = format!("{key}={default}");
                out += &format!("    {assignment:<width$}  {help}\n");
            }
        } else {
            out += &format!("{:<10} {}D  {}\n", i.name, i.dim, i.summary);
        }
    }
    out += "scene pixels (4D, no closed form): scene:NAME,px=X,py=Y with NAME a scene of \
            `varspec render --list` or a scene file; for predict --method empirical, optimize \
            shear and spectrum --integrand\n";
    out += "spec syntax: name:key=value,key=value (e.g. disk:r=0.3,cx=0.5,cy=0.5)";
    if !a.list {
        out += "; parameters: varspec integrands --list";
    }
    out += "\n";
    super::stdout::bytes(out.as_bytes());
    Ok(())
}
