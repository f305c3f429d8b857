//! The figure flags of a model binary, `--png`, `--png-size`, `--animate` and
//! `--animate-every`, declared once: every binary takes them with the same ids, kinds, value
//! names, ranges and rules, and only their help texts (which name the model's files and what
//! they show) differ, given by the model through [`FigureHelp`].

use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use std::marker::PhantomData;

/// The help texts of a binary's figure flags ([`FigureArgs`]), as clap's derive would show
/// the doc comments (one paragraph, no final full stop).
pub trait FigureHelp {
    /// `--png`: write the still figure; `None` for a binary without the flag (animat, whose
    /// still figures are `--snapshot-every`'s).
    const PNG: Option<&'static str>;
    /// `--png-size PX`: the side of the figures.
    const PNG_SIZE: &'static str;
    /// `--animate`: write the animation.
    const ANIMATE: &'static str;
    /// `--animate-every N`: the steps between its frames.
    const ANIMATE_EVERY: &'static str;
}

/// The figure flags, `#[command(flatten)]`ed into a binary's flags where they are shown, with
/// the help texts of `H`; after parsing, their values. The arg ids are the fields' names
/// (`png`, `png_size`, `animate`, `animate_every`: config files and `--dump-config` use them).
pub struct FigureArgs<H> {
    /// `--png` (always false where `H` has no such flag).
    pub png: bool,
    /// `--png-size PX`, in [`figures::PNG_SIZE_MIN`]`..=`[`figures::PNG_SIZE_MAX`].
    pub png_size: Option<u32>,
    /// `--animate`.
    pub animate: bool,
    /// `--animate-every N` (only with `--animate`).
    pub animate_every: Option<u64>,
    _help: PhantomData<fn() -> H>,
}

impl<H> FigureArgs<H> {
    /// The checks every binary makes of its figure flags
    /// ([`figures::animation::check_figure_flags`]), `--png` being the flag of the still
    /// figures.
    ///
    /// # Errors
    /// One line naming the flag and what it accepts.
    pub fn check(&self) -> Result<(), String> {
        self.check_with(self.png, "--png")
    }

    /// [`check`](Self::check) for a binary whose still figures come from another flag,
    /// `stills`, given or not as `still`.
    ///
    /// # Errors
    /// One line naming the flag and what it accepts.
    pub fn check_with(&self, still: bool, stills: &str) -> Result<(), String> {
        figures::animation::check_figure_flags(
            self.png_size,
            self.animate,
            self.animate_every,
            still,
            stills,
        )
    }
}

// By hand, so that neither needs `H: Debug` or `H: Clone` (`H` only names the help texts).
impl<H> std::fmt::Debug for FigureArgs<H> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FigureArgs")
            .field("png", &self.png)
            .field("png_size", &self.png_size)
            .field("animate", &self.animate)
            .field("animate_every", &self.animate_every)
            .finish()
    }
}

impl<H> Clone for FigureArgs<H> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<H> Copy for FigureArgs<H> {}

impl<H: FigureHelp> Args for FigureArgs<H> {
    // What `#[arg(long)] png: bool`, `#[arg(long, value_name = "PX", value_parser = ...)]
    // png_size: Option<u32>` and so on build with clap's derive, the help texts from `H`.
    fn augment_args(cmd: Command) -> Command {
        let cmd = match H::PNG {
            Some(help) => cmd.arg(
                Arg::new("png")
                    .long("png")
                    .action(ArgAction::SetTrue)
                    .help(help),
            ),
            None => cmd,
        };
        cmd.arg(
            Arg::new("png_size")
                .long("png-size")
                .value_name("PX")
                .action(ArgAction::Set)
                .value_parser(
                    clap::value_parser!(u32)
                        .range(i64::from(figures::PNG_SIZE_MIN)..=i64::from(figures::PNG_SIZE_MAX)),
                )
                .help(H::PNG_SIZE),
        )
        .arg(
            Arg::new("animate")
                .long("animate")
                .action(ArgAction::SetTrue)
                .help(H::ANIMATE),
        )
        .arg(
            Arg::new("animate_every")
                .long("animate-every")
                .value_name("N")
                .requires("animate")
                .action(ArgAction::Set)
                .value_parser(run_io::count::count::<u64>)
                .help(H::ANIMATE_EVERY),
        )
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl<H: FigureHelp> FromArgMatches for FigureArgs<H> {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        Ok(FigureArgs {
            png: H::PNG.is_some() && m.get_flag("png"),
            png_size: m.get_one::<u32>("png_size").copied(),
            animate: m.get_flag("animate"),
            animate_every: m.get_one::<u64>("animate_every").copied(),
            _help: PhantomData,
        })
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{CommandFactory, Parser};

    struct WithPng;
    impl FigureHelp for WithPng {
        const PNG: Option<&'static str> = Some("Write toy.png");
        const PNG_SIZE: &'static str = "Side of toy.png";
        const ANIMATE: &'static str = "Write toy.gif";
        const ANIMATE_EVERY: &'static str = "Steps between frames";
    }

    struct WithoutPng;
    impl FigureHelp for WithoutPng {
        const PNG: Option<&'static str> = None;
        const PNG_SIZE: &'static str = "Side of the snapshots";
        const ANIMATE: &'static str = "Write toy.gif";
        const ANIMATE_EVERY: &'static str = "Steps between frames";
    }

    #[derive(Parser, Debug)]
    struct Toy<H: FigureHelp + 'static> {
        #[command(flatten)]
        figure: FigureArgs<H>,
        #[arg(long)]
        snapshots: bool,
    }

    fn parse<H: FigureHelp + 'static>(args: &[&str]) -> Result<FigureArgs<H>, clap::Error> {
        Toy::<H>::try_parse_from(std::iter::once("toy").chain(args.iter().copied()))
            .map(|t| t.figure)
    }

    #[test]
    fn the_flags_parse_with_their_ranges_and_rules() {
        Toy::<WithPng>::command().debug_assert();
        Toy::<WithoutPng>::command().debug_assert();
        let f = parse::<WithPng>(&[
            "--png",
            "--png-size",
            "600",
            "--animate",
            "--animate-every",
            "1e2",
        ])
        .unwrap();
        assert!(f.png && f.animate);
        assert_eq!((f.png_size, f.animate_every), (Some(600), Some(100)));
        let f = parse::<WithPng>(&[]).unwrap();
        assert!(!f.png && !f.animate && f.png_size.is_none() && f.animate_every.is_none());
        // --animate-every needs --animate; --png-size has the figures' range.
        assert!(parse::<WithPng>(&["--animate-every", "3"]).is_err());
        assert!(parse::<WithPng>(&["--png-size", "5"]).is_err());
        assert!(parse::<WithPng>(&["--png-size", "65537"]).is_err());
        // Without --png the flag does not exist.
        assert!(parse::<WithoutPng>(&["--png"]).is_err());
        let f = parse::<WithoutPng>(&["--png-size", "512"]).unwrap();
        assert!(!f.png && f.png_size == Some(512));
        assert!(
            f.check().unwrap_err().contains("--png and --animate"),
            "{:?}",
            f.check()
        );
        assert!(f.check_with(true, "--snapshot-every").is_ok());
    }

    #[test]
    fn the_help_is_the_models() {
        let help = Toy::<WithPng>::command().render_help().to_string();
        let line = |flag: &str| {
            help.lines()
                .find(|l| l.trim_start().starts_with(flag))
                .map(|l| l.split_whitespace().collect::<Vec<_>>().join(" "))
        };
        assert_eq!(line("--png ").as_deref(), Some("--png Write toy.png"));
        assert_eq!(
            line("--png-size").as_deref(),
            Some("--png-size <PX> Side of toy.png")
        );
        assert_eq!(
            line("--animate ").as_deref(),
            Some("--animate Write toy.gif")
        );
        assert_eq!(
            line("--animate-every").as_deref(),
            Some("--animate-every <N> Steps between frames")
        );
        let help = Toy::<WithoutPng>::command().render_help().to_string();
        assert!(!help.contains("--png ") && help.contains("Side of the snapshots"));
    }
}
