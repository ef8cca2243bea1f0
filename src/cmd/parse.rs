//! clap value parsers for numeric flags whose messages name the flag and its range, so
//! `--grad-bits 99999999999999`, `--grad-bits -1` and `--size -5` say what is allowed
//! (`--grad-bits must be in 8..=16, not -1`) instead of a parse error about the integer
//! type. Ranges come from where they are defined ([`crate::config::RANGES`],
//! [`crate::config::PIPELINE_DEPTHS`], the commands' constants); nothing is retyped.

use clap::builder::TypedValueParser;
use clap::error::ErrorKind;
use std::ffi::OsStr;
use std::marker::PhantomData;

/// How an argument is named in messages: `--long`, or the value name of a positional.
pub fn flag_name(arg: Option<&clap::Arg>) -> String {
    match arg {
        Some(a) => match a.get_long() {
            Some(l) => format!("--{l}"),
            None => a.get_id().to_string(),
        },
        None => "value".into(),
    }
}

fn fail(cmd: &clap::Command, msg: String) -> clap::Error {
    clap::Error::raw(ErrorKind::ValueValidation, msg).with_cmd(cmd)
}

fn text<'a>(
    cmd: &clap::Command,
    arg: Option<&clap::Arg>,
    v: &'a OsStr,
) -> Result<&'a str, clap::Error> {
    v.to_str().map(str::trim).ok_or_else(|| {
        fail(
            cmd,
            format!("{} must be a number, not {v:?}", flag_name(arg)),
        )
    })
}

/// A whole number in `min..=max` (`max` None: no upper limit but the type's).
#[derive(Clone)]
pub struct Whole<T> {
    min: u64,
    max: Option<u64>,
    /// Only a sign check ("must be a positive whole number"): the command checks the range.
    sign_only: bool,
    ty: PhantomData<fn() -> T>,
}

/// A whole number in `min..=max`.
pub fn whole<T>(min: u64, max: u64) -> Whole<T> {
    Whole {
        min,
        max: Some(max),
        sign_only: false,
        ty: PhantomData,
    }
}

/// A whole number >= `min`.
pub fn at_least<T>(min: u64) -> Whole<T> {
    Whole {
        min,
        max: None,
        sign_only: false,
        ty: PhantomData,
    }
}

/// A count or size: a negative number or a non-number says it must be a positive whole
/// number; the command checks the range itself.
pub fn count<T>() -> Whole<T> {
    Whole {
        min: 0,
        max: None,
        sign_only: true,
        ty: PhantomData,
    }
}

/// The range of a configuration field, from [`crate::config::range_of`].
pub fn field(name: &str) -> Whole<u32> {
    let (min, max) = crate::config::range_of(name).expect("a configuration field with a range");
    whole(min as u64, max as u64)
}

/// The help of a configuration field's flag: `what [min..=max<note>, default d]`, the range
/// from [`crate::config::range_of`] and the default from [`crate::config::Config::default`].
pub fn field_help(name: &str, what: &str, note: &str) -> String {
    let (min, max) = crate::config::range_of(name).expect("a configuration field with a range");
    let d = crate::config::Config::default();
    let default = match name {
        "pipeline_depth" => d.pipeline_depth,
        "axis_user" => d.axis_user,
        "lanes" => d.lanes,
        _ => d.field(name),
    };
    format!("{what} [{min}..={max}{note}, default {default}]")
}

impl<T> TypedValueParser for Whole<T>
where
    T: TryFrom<u64> + Clone + Send + Sync + 'static,
{
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<T, clap::Error> {
        let name = flag_name(arg);
        let s = text(cmd, arg, value)?;
        let want = match self.max {
            None if self.sign_only => format!("{name} must be a positive whole number"),
            Some(max) => format!("{name} must be in {}..={max}", self.min),
            None if self.min == 0 => format!("{name} must be a whole number >= 0"),
            None if self.min == 1 => format!("{name} must be a positive whole number"),
            None => format!("{name} must be a whole number >= {}", self.min),
        };
        let n: i128 = match s.parse() {
            Ok(n) => n,
            // Digits that do not fit any integer: out of range, not "not a number".
            Err(_)
                if !s.is_empty()
                    && s.trim_start_matches(['-', '+'])
                        .bytes()
                        .all(|b| b.is_ascii_digit()) =>
            {
                return Err(fail(cmd, format!("{want}, not {s}")))
            }
            Err(_) => return Err(fail(cmd, format!("{want}, not '{s}'"))),
        };
        let max = self.max.unwrap_or(u64::MAX);
        if n < self.min as i128 || n > max as i128 {
            return Err(fail(cmd, format!("{want}, not {s}")));
        }
        T::try_from(n as u64).map_err(|_| fail(cmd, format!("{want}, not {s} (too large)")))
    }
}

/// A [`crate::config::Config::prefix`], checked by [`crate::config::check_prefix`]:
/// `--prefix 9a` says `--prefix "9a" starts with a digit; allowed ...`.
#[derive(Clone)]
pub struct Prefix;

pub fn prefix() -> Prefix {
    Prefix
}

/// The help of `--prefix`.
pub fn prefix_help() -> String {
    format!(
        "Prefix of every generated module, file, hex file and of the FuseSoC core's name, so two \
         designs can share a project: a letter or _, then letters, digits and _, at most {} \
         [default: none]",
        crate::config::PREFIX_MAX_LEN
    )
}

impl TypedValueParser for Prefix {
    type Value = String;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<String, clap::Error> {
        let name = flag_name(arg);
        let s = value
            .to_str()
            .ok_or_else(|| fail(cmd, format!("{name} {value:?} is not UTF-8")))?;
        crate::config::check_prefix(s)
            .map(|()| s.to_string())
            .map_err(|why| fail(cmd, format!("{name} {s:?} {why}")))
    }
}

/// A finite number above `min` (or at least `min` when `inclusive`).
#[derive(Clone)]
pub struct Real {
    min: f64,
    inclusive: bool,
}

/// A finite number > 0.
pub fn positive() -> Real {
    Real {
        min: 0.0,
        inclusive: false,
    }
}

/// A finite number >= 0.
pub fn non_negative() -> Real {
    Real {
        min: 0.0,
        inclusive: true,
    }
}

impl TypedValueParser for Real {
    type Value = f64;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<f64, clap::Error> {
        let name = flag_name(arg);
        let s = text(cmd, arg, value)?;
        let want = if self.min == 0.0 && !self.inclusive {
            format!("{name} must be a positive number")
        } else {
            format!(
                "{name} must be a finite number {} {}",
                if self.inclusive { ">=" } else { ">" },
                self.min
            )
        };
        match s.parse::<f64>() {
            Ok(x) if x.is_finite() && (x > self.min || (self.inclusive && x == self.min)) => Ok(x),
            _ => Err(fail(cmd, format!("{want}, not {s}"))),
        }
    }
}

/// A value read by a function whose error says what is wrong with it (without the flag):
/// the error is one line naming the flag and the value, `--shard -1/2: K is not a whole
/// number`. Give such a flag `allow_hyphen_values`, so a value starting with '-' (`-1/2`,
/// `-1:5,0:3,0:3`) reaches the function instead of clap's "unexpected argument '-1'".
#[derive(Clone)]
pub struct Named<T>(fn(&str) -> Result<T, String>);

pub fn named<T>(read: fn(&str) -> Result<T, String>) -> Named<T> {
    Named(read)
}

impl<T: Clone + Send + Sync + 'static> TypedValueParser for Named<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<T, clap::Error> {
        let name = flag_name(arg);
        let s = value
            .to_str()
            .ok_or_else(|| fail(cmd, format!("{name} {value:?} is not UTF-8")))?;
        (self.0)(s).map_err(|why| fail(cmd, format!("{name} {s}: {why}")))
    }
}
