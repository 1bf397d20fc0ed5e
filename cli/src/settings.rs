//! The render settings on the command line, made from the library's schema: every setting
//! is a `--NAME VALUE` flag (underscores as dashes) and `--set NAME=VALUE`, so a setting
//! added to the schema is on the command line with its doc, range and default, with no
//! line here.

use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use hairtrace::render::settings::{Needs, RenderSettings};

/// The settings a command line gives, in the order they apply: flags, then `--set`.
#[derive(Debug, Default, Clone)]
pub struct SettingArgs {
    pub values: Vec<(String, String)>,
}

fn flag(name: &str) -> String {
    name.replace('_', "-")
}

impl SettingArgs {
    /// Applies every value to `settings`; an error names the flag.
    pub fn apply(&self, settings: &mut RenderSettings) -> hairtrace::Result<()> {
        for (key, value) in &self.values {
            settings.set(key, value)?;
        }
        Ok(())
    }
}

impl FromArgMatches for SettingArgs {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut values = Vec::new();
        for s in RenderSettings::schema() {
            if let Some(v) = m.get_one::<String>(s.name) {
                values.push((s.name.to_owned(), v.clone()));
            }
        }
        for pair in m.get_many::<String>("set").into_iter().flatten() {
            let Some((key, value)) = pair.split_once('=') else {
                return Err(clap::Error::raw(
                    clap::error::ErrorKind::InvalidValue,
                    format!("--set {pair:?}: must be NAME=VALUE\n"),
                ));
            };
            values.push((key.trim().to_owned(), value.trim().to_owned()));
        }
        Ok(SettingArgs { values })
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl Args for SettingArgs {
    fn augment_args(cmd: Command) -> Command {
        let cmd = RenderSettings::schema().iter().fold(cmd, |cmd, s| {
            cmd.arg(
                Arg::new(s.name)
                    .long(flag(s.name))
                    .value_name("VALUE")
                    .help(format!(
                        "{} [{}; default {}]",
                        s.doc(),
                        s.allowed(),
                        s.default_text()
                    ))
                    .help_heading("Render settings (also --set NAME=VALUE; docs/settings.md)"),
            )
        });
        cmd.arg(
            Arg::new("set")
                .long("set")
                .value_name("NAME=VALUE")
                .action(ArgAction::Append)
                .help("Any render setting by its name, after the flags; repeatable")
                .help_heading("Render settings (also --set NAME=VALUE; docs/settings.md)"),
        )
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

/// One more render of the same build (`render --variant 'OUT:NAME=VALUE ...'`): its image
/// and the settings it changes, after every other flag.
#[derive(Debug, Clone)]
pub struct Variant {
    pub output: std::path::PathBuf,
    pub values: SettingArgs,
}

impl Variant {
    /// `OUT:NAME=VALUE NAME=VALUE ...`: the image, then settings separated by spaces (no
    /// setting's value holds a colon, so the output is what comes before the last one).
    pub fn parse(text: &str) -> Result<Variant, String> {
        let (output, sets) = text
            .rsplit_once(':')
            .filter(|(o, _)| !o.is_empty())
            .ok_or_else(|| format!("{text:?}: must be OUT:NAME=VALUE [NAME=VALUE ...]"))?;
        let values = (sets.split_whitespace())
            .map(|pair| {
                let (k, v) = pair
                    .split_once('=')
                    .ok_or_else(|| format!("{text:?}: {pair:?} must be NAME=VALUE"))?;
                Ok((k.to_owned(), v.to_owned()))
            })
            .collect::<Result<Vec<_>, String>>()?;
        if values.is_empty() {
            return Err(format!(
                "{text:?}: give at least one NAME=VALUE after the colon"
            ));
        }
        Ok(Variant {
            output: output.into(),
            values: SettingArgs { values },
        })
    }

    /// `base` with this variant's values, checked.
    pub fn settings(&self, base: &RenderSettings) -> hairtrace::Result<RenderSettings> {
        let mut settings = *base;
        self.values.apply(&mut settings)?;
        settings.validate()?;
        Ok(settings)
    }
}

/// The schema as a Markdown table: what `hairtrace settings` prints and docs/settings.md
/// holds (cli/tests checks that the two agree).
pub fn markdown() -> String {
    let mut out = String::from(
        "| name | value | default | a change builds again | what it does |\n|---|---|---|---|---|\n",
    );
    for s in RenderSettings::schema() {
        out += &format!(
            "| `{}` | {} | `{}` | {} | {} |\n",
            s.name,
            s.allowed().replace('|', "\\|"),
            s.default_text(),
            if s.needs == Needs::Build { "yes" } else { "" },
            s.doc().replace('|', "\\|")
        );
    }
    out
}
