//! How a calibration's JSON reads back where it is lenient: a field that a hand-edited or older
//! file lacks or holds in another shape reads as the value that says least, instead of refusing
//! a calibration whose models are fine. (A NaN is written as `null`, so a figure that was NaN
//! reads back this way too.)

use std::collections::BTreeMap;

use serde::de::{DeserializeOwned, Deserializer, Error, IgnoredAny, MapAccess, Visitor};
use serde::Deserialize;
use serde_json::Value;

use super::{Method, Sensor, SensorModel};

/// The value, or `None` where it does not read as one.
pub(crate) fn or_none<'de, D: Deserializer<'de>, T: DeserializeOwned>(
    de: D,
) -> Result<Option<T>, D::Error> {
    Ok(T::deserialize(Value::deserialize(de)?).ok())
}

/// The value, or the type's default where it does not read as one.
pub(crate) fn or_default<'de, D: Deserializer<'de>, T: DeserializeOwned + Default>(
    de: D,
) -> Result<T, D::Error> {
    Ok(or_none(de)?.unwrap_or_default())
}

/// A flag that holds unless it says `false`.
pub(crate) fn true_unless_false<'de, D: Deserializer<'de>>(de: D) -> Result<bool, D::Error> {
    Ok(Value::deserialize(de)?.as_bool().unwrap_or(true))
}

/// What an absent flag read by [`true_unless_false`] is.
pub(crate) fn yes() -> bool {
    true
}

/// A number, or NaN where there is none.
pub(crate) fn number_or_nan<'de, D: Deserializer<'de>>(de: D) -> Result<f64, D::Error> {
    Ok(Value::deserialize(de)?.as_f64().unwrap_or(f64::NAN))
}

/// What an absent number read by [`number_or_nan`] is.
pub(crate) fn nan() -> f64 {
    f64::NAN
}

/// The items of a list that read as `T` (the others dropped); none where it is not a list.
pub(crate) fn readable_items<'de, D: Deserializer<'de>, T: DeserializeOwned>(
    de: D,
) -> Result<Vec<T>, D::Error> {
    Ok(match Value::deserialize(de)? {
        Value::Array(items) => items
            .into_iter()
            .filter_map(|item| T::deserialize(item).ok())
            .collect(),
        _ => Vec::new(),
    })
}

/// The value, with `null` read as absent.
pub(crate) fn null_as_default<'de, D: Deserializer<'de>, T: Deserialize<'de> + Default>(
    de: D,
) -> Result<T, D::Error> {
    Ok(Option::<T>::deserialize(de)?.unwrap_or_default())
}

/// A method by its name; anything else refused, naming every method.
pub(crate) fn method<'de, D: Deserializer<'de>>(de: D) -> Result<Method, D::Error> {
    let name = Value::deserialize(de)?;
    name.as_str().and_then(Method::from_name).ok_or_else(|| {
        D::Error::custom(format!(
            "`method` must be {}, found {}",
            method_names(),
            shown(&name)
        ))
    })
}

/// The sensor models by sensor name. A name this version does not know and a `null` model are
/// skipped (a sensor a newer file adds reads as absent); a model whose standard errors do not
/// count one per coefficient is refused (it describes another model).
pub(crate) fn sensors<'de, D: Deserializer<'de>>(
    de: D,
) -> Result<BTreeMap<Sensor, SensorModel>, D::Error> {
    de.deserialize_any(SensorsByName)
}

struct SensorsByName;

impl<'de> Visitor<'de> for SensorsByName {
    type Value = BTreeMap<Sensor, SensorModel>;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("an object of sensor models by sensor name")
    }

    fn visit_unit<E>(self) -> Result<Self::Value, E> {
        Ok(BTreeMap::new())
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let mut sensors = BTreeMap::new();
        while let Some(name) = map.next_key::<String>()? {
            let Some(sensor) = Sensor::ALL.into_iter().find(|s| s.name() == name) else {
                map.next_value::<IgnoredAny>()?;
                continue;
            };
            let Some(model) = map.next_value::<Option<SensorModel>>()? else {
                continue;
            };
            for (sd, given, of, n) in [
                ("alpha_sd", &model.alpha_sd, "alpha", model.alpha.len()),
                ("beta_sd", &model.beta_sd, "beta", model.beta.len()),
            ] {
                if !given.is_empty() && given.len() != n {
                    return Err(A::Error::custom(format!(
                        "sensors.{name}.{sd} has {} standard errors for {n} {of} coefficients",
                        given.len()
                    )));
                }
            }
            sensors.insert(sensor, model);
        }
        Ok(sensors)
    }
}

/// Every method's name, for a message: `em, landmarks, groundtruth or odometry`.
fn method_names() -> String {
    let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
    match names.split_last() {
        Some((last, [])) => (*last).to_string(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// A JSON value for a message: terminal-safe and short.
pub(crate) fn shown(value: &Value) -> String {
    hilsim_recording::printable_cut(&value.to_string(), 60).into_owned()
}
