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
    pub help: &'static str,
}

impl Knob {
    /// A knob that is off (0, the default) or on (1).
    pub const fn switch(name: &'static str, help: &'static str) -> Self {
        Knob { name, default: 0.0, min: 0.0, max: 1.0, integer: true, help }
    }
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
        let v: f64 = value
            .trim()
            .parse()
            .map_err(|_| Error::Invalid(format!("knob `{key}` of `{}`: `{value}` is not a number", t.name)))?;
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

/// `name=value` for every knob, in declaration order.
impl std::fmt::Display for Params {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let pairs: Vec<_> =
            self.technique.knobs.iter().map(|k| format!("{}={}", k.name, self.values[k.name])).collect();
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
}
