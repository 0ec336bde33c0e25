//! `varspec integrands --list`: the reference integrands and their parameters.

use varspec::integrands::INTEGRANDS;

#[derive(clap::Args)]
pub struct Args {
    /// List every integrand with its parameters (the default).
    #[arg(long)]
    list: bool,
}

pub fn run(_a: Args) -> anyhow::Result<()> {
    let mut out = String::new();
    for i in INTEGRANDS {
        out += &format!("{} ({}D)\n    {}\n", i.name, i.dim, i.summary);
        for (key, default, help) in i.params {
            out += &format!("    {key}={default:<6} {help}\n");
        }
    }
    out += "spec syntax: name:key=value,key=value (e.g. disk:r=0.3,cx=0.5,cy=0.5)\n";
    print!("{out}");
    Ok(())
}
