//! The render settings as command-line options: one option for each entry
//! of the request's settings table ([`sahara_formats::SETTINGS`]), its
//! help, value and checks from there, its value put into the caller's
//! settings layer by the table. The command line names no setting of its
//! own: a setting added to the table is an option here.

use clap::builder::{PossibleValue, StringValueParser, TypedValueParser};
use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use sahara_formats::{Given, Setting, SettingsLayer, Takes, SETTINGS};

/// The settings given on the command line, as the caller's layer.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SettingArgs(pub SettingsLayer);

impl FromArgMatches for SettingArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let mut args = SettingArgs::default();
        args.update_from_arg_matches(matches)?;
        Ok(args)
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        for s in SETTINGS {
            let given = match s.takes {
                Takes::Switch => matches.get_flag(s.name).then_some(Given::Flag(true)),
                Takes::Names(_) => matches
                    .get_many::<String>(s.name)
                    .map(|v| Given::List(v.cloned().map(Given::Text).collect())),
                Takes::Value | Takes::Name(_) => {
                    matches.get_one::<String>(s.name).cloned().map(Given::Text)
                }
            };
            if let Some(given) = given {
                // Each value was checked by its parser (`SettingParser`).
                s.set(&mut self.0, &given).map_err(|e| {
                    clap::Error::raw(
                        clap::error::ErrorKind::ValueValidation,
                        format!("{}: {e}\n", s.flag()),
                    )
                })?;
            }
        }
        Ok(())
    }
}

impl Args for SettingArgs {
    fn augment_args(cmd: Command) -> Command {
        SETTINGS.iter().fold(cmd, |cmd, s| cmd.arg(option(s)))
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

/// The option of setting `s`.
fn option(s: &'static Setting) -> Arg {
    let mut arg = Arg::new(s.name)
        .long(s.flag().trim_start_matches('-').to_string())
        .help(s.help);
    if let Some(c) = s.short {
        arg = arg.short(c);
    }
    if let Some(other) = s.requires {
        arg = arg.requires(other);
    }
    if let Takes::Switch = s.takes {
        return arg.action(ArgAction::SetTrue);
    }
    let arg = arg
        .value_name(s.value_name)
        .allow_negative_numbers(true)
        .value_parser(SettingParser(s));
    match s.takes {
        Takes::Names(_) => arg.value_delimiter(',').action(ArgAction::Append),
        Takes::Value | Takes::Name(_) | Takes::Switch => arg,
    }
}

/// Checks one value of a setting as the table parses it, so a wrong one is
/// refused by clap's parser (with its `invalid value` line and the names
/// it takes) before anything runs.
#[derive(Clone, Copy)]
struct SettingParser(&'static Setting);

impl TypedValueParser for SettingParser {
    type Value = String;

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<String, clap::Error> {
        let setting = self.0;
        StringValueParser::new()
            .try_map(move |text| {
                let mut scratch = SettingsLayer::default();
                let given = match setting.takes {
                    // One name of a list at a time (the option splits at commas).
                    Takes::Names(_) => Given::List(vec![Given::Text(text.clone())]),
                    _ => Given::Text(text.clone()),
                };
                setting
                    .set(&mut scratch, &given)
                    .map(|()| text)
                    .map_err(|e| e.to_string())
            })
            .parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        match self.0.takes {
            Takes::Name(names) | Takes::Names(names) => {
                Some(Box::new(names().into_iter().map(PossibleValue::new)))
            }
            Takes::Value | Takes::Switch => None,
        }
    }
}
