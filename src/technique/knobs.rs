//! Technique knobs as data: what `softshadow techniques` lists, and what scene files and
//! `--set KEY=VALUE` are checked against. A technique reads its knobs through the [`Knob`]
//! constants it declares, so a misspelled name does not compile.

use std::collections::BTreeMap;

use super::registry::TechniqueInfo;
use crate::error::{Error, Result};

/// One tunable number of a technique.
#[derive(Clone, Copy, Debug)]
pub struct Knob {
    pub name: &'static str,
    pub default: f64,
    pub min: f64,
    pub max: f64,
    /// Only whole numbers are accepted.
    pub integer: bool,
    /// Names of the whole values from 0 up, each accepted in place of its number
    /// (`penumbra=outer`); `|` separates a name's spellings (`centred|centered`).
    pub choices: &'static [&'static str],
    pub help: &'static str,
}

/// What a switch's values are called.
const OFF_ON: &[&str] = &["off|false", "on|true"];

impl Knob {
    /// A knob that is off (0, the default) or on (1).
    pub const fn switch(name: &'static str, help: &'static str) -> Self {
        Knob { name, default: 0.0, min: 0.0, max: 1.0, integer: true, choices: OFF_ON, help }
    }

    /// A knob choosing one of `choices`, by name or by number (0, 1, …).
    pub const fn choice(
        name: &'static str,
        default: f64,
        choices: &'static [&'static str],
        help: &'static str,
    ) -> Self {
        Knob { name, default, min: 0.0, max: (choices.len() - 1) as f64, integer: true, choices, help }
    }

    /// The value a name of `choices` stands for.
    pub(crate) fn named(&self, name: &str) -> Option<f64> {
        let name = name.trim();
        self.choices.iter().position(|c| c.split('|').any(|n| n.eq_ignore_ascii_case(name))).map(|i| i as f64)
    }

    /// `value` as `--set` and scene files take it: the name of a named choice (its first
    /// spelling), else the number.
    pub fn show(&self, value: f64) -> String {
        let index = (value.fract() == 0.0 && value >= 0.0).then_some(value as usize);
        match index.and_then(|i| self.choices.get(i)) {
            Some(choice) => first_spelling(choice).to_string(),
            None => value.to_string(),
        }
    }

    /// `choices` for a listing: `0 outer, 1 centred`, a name's first spelling only.
    pub fn choice_list(&self) -> String {
        let names: Vec<_> =
            self.choices.iter().map(|c| first_spelling(c)).enumerate().map(|(i, n)| format!("{i} {n}")).collect();
        names.join(", ")
    }
}

/// The name a choice is shown by: the first of its `|`-separated spellings.
fn first_spelling(choice: &str) -> &str {
    choice.split('|').next().unwrap_or_default()
}

/// Validated knob values of one technique; unset knobs take their defaults.
#[derive(Clone, Debug)]
pub struct Params {
    pub technique: &'static TechniqueInfo,
    values: BTreeMap<&'static str, f64>,
}

impl Params {
    /// Every knob at its default.
    pub fn defaults(technique: &'static TechniqueInfo) -> Self {
        Params { technique, values: technique.knobs.iter().map(|k| (k.name, k.default)).collect() }
    }

    /// Sets `key` from text, checking that the knob exists and the value is in range.
    pub fn set(&mut self, key: &str, value: &str) -> Result<()> {
        let t = self.technique;
        let knob = t.knobs.iter().find(|k| k.name == key).ok_or_else(|| {
            let names: Vec<_> = t.knobs.iter().map(|k| k.name).collect();
            Error::Invalid(format!("technique `{}` has no knob `{key}` (knobs: {})", t.name, names.join(", ")))
        })?;
        let v: f64 = knob.named(value).map_or_else(|| value.trim().parse(), Ok).map_err(|_| {
            let names: Vec<_> = knob.choices.iter().flat_map(|c| c.split('|')).collect();
            let what = match names[..] {
                [] => "not a number".to_string(),
                _ => format!("neither a number nor one of {}", names.join(", ")),
            };
            Error::Invalid(format!("knob `{key}` of `{}`: `{value}` is {what}", t.name))
        })?;
        if !v.is_finite() || v < knob.min || v > knob.max || (knob.integer && v.fract() != 0.0) {
            let kind = if knob.integer { "a whole number" } else { "a number" };
            return Err(Error::Invalid(format!(
                "knob `{key}` of `{}`: {value} is out of range (want {kind} in {}..={})",
                t.name, knob.min, knob.max
            )));
        }
        self.values.insert(knob.name, v);
        Ok(())
    }

    /// Applies `KEY=VALUE` pairs in order.
    pub fn apply<'a>(&mut self, pairs: impl IntoIterator<Item = (&'a str, &'a str)>) -> Result<()> {
        pairs.into_iter().try_for_each(|(k, v)| self.set(k, v))
    }

    /// The value of `knob`, one the technique declares (debug builds check that it does).
    pub fn get(&self, knob: &Knob) -> f64 {
        debug_assert!(
            self.values.contains_key(knob.name),
            "`{}` reads undeclared knob `{}`",
            self.technique.name,
            knob.name
        );
        self.values.get(knob.name).copied().unwrap_or(knob.default)
    }

    /// An on/off knob (0 or 1) is on.
    pub fn is_on(&self, knob: &Knob) -> bool {
        self.get(knob) != 0.0
    }
}

/// `name=value` for every knob, in declaration order, each value as [`Knob::show`] gives it:
/// what `--set` takes back.
impl std::fmt::Display for Params {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let pairs: Vec<_> =
            self.technique.knobs.iter().map(|k| format!("{}={}", k.name, k.show(self.values[k.name]))).collect();
        f.write_str(&pairs.join(" "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::technique::registry::find;

    #[test]
    fn bad_knobs_are_named() {
        let mut p = Params::defaults(find("shadow-map").unwrap());
        let e = p.set("no_such", "1").unwrap_err().to_string();
        assert!(e.contains("no_such") && e.contains("shadow_map_size"), "{e}");
        let e = p.set("shadow_map_size", "1.5").unwrap_err().to_string();
        assert!(e.contains("whole number"), "{e}");
        assert!(p.set("shadow_map_size", "nan").is_err());
        assert!(find("plateu").unwrap_err().to_string().contains("plateu"));
    }

    /// Issue 20 names the penumbra knob's values `outer | centered`: a knob's values may be given
    /// by name, in any case and any listed spelling, or by number, and a name it does not have is
    /// an error listing those it has.
    #[test]
    fn named_values_stand_for_their_numbers() {
        let mut p = Params::defaults(find("plateau").unwrap());
        let penumbra = &crate::technique::falloff::PENUMBRA;
        p.set("penumbra", "outer").unwrap();
        assert_eq!(p.get(penumbra), 0.0);
        for centred in ["centred", "Centered", " centered ", "1"] {
            p.set("penumbra", "outer").unwrap();
            p.set("penumbra", centred).unwrap();
            assert_eq!(p.get(penumbra), 1.0, "{centred}");
        }
        p.set("falloff", "disk").unwrap();
        assert_eq!(p.get(&crate::technique::falloff::FALLOFF), 3.0);
        let e = p.set("penumbra", "inner").unwrap_err().to_string();
        assert!(e.contains("`inner`") && e.contains("outer, centred, centered"), "{e}");
        // A knob without names takes numbers only, and says so.
        let e = p.set("penumbra_scale", "wide").unwrap_err().to_string();
        assert!(e.ends_with("is not a number"), "{e}");
        assert_eq!(penumbra.choice_list(), "0 outer, 1 centred");
    }

    /// What compare, render's timings and the window print of the knobs names their values as
    /// `--set` takes them, and reads back as the same values, for every technique.
    #[test]
    fn shown_knobs_name_their_values_and_read_back() {
        let mut p = Params::defaults(find("plateau").unwrap());
        p.apply([("penumbra", "outer"), ("falloff", "linear"), ("penumbra_scale", "0.4")]).unwrap();
        let shown = p.to_string();
        for pair in ["penumbra=outer", "falloff=linear", "penumbra_scale=0.4", "texture_size=1024"] {
            assert!(shown.split(' ').any(|s| s == pair), "{pair} in {shown}");
        }
        for &technique in crate::technique::TECHNIQUES {
            let p = Params::defaults(technique);
            let mut back = Params::defaults(technique);
            back.apply(p.to_string().split(' ').filter_map(|pair| pair.split_once('='))).unwrap();
            assert_eq!(back.to_string(), p.to_string(), "{}", technique.name);
            assert!(technique.knobs.iter().all(|k| back.get(k) == p.get(k)), "{}", technique.name);
        }
    }
}
