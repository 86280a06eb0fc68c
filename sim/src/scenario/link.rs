//! `[link]`: how the serial link and the unit's motor fail as a real XV-11's do, for `hilsim
//! serve` and `hilsim hil` (off by default: a perfect stream). The wire faults (corrupted
//! packets, dropped bytes and packets, a disconnection) touch only the bytes on the wire; the
//! motor's spin-up is the unit's physics, so a recording of the scenario carries it too.

use serde::Deserialize;

use super::check::toml_number;

/// The `[link]` table as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Link {
    /// A named set of the values below (`"xv11-capture"`: [`XV11_CAPTURE`]); keys given beside
    /// it override its values.
    pub profile: Option<String>,
    /// Fraction of packets with a byte flipped so that their checksum fails.
    pub corrupt_packet_rate: Option<f64>,
    /// Fraction of bytes lost on the wire.
    pub dropped_byte_rate: Option<f64>,
    /// Fraction of whole packets the unit does not send.
    pub dropped_packet_rate: Option<f64>,
    /// The motor spins up from [`SPIN_UP_FROM_RPM`] to its speed over this many seconds after
    /// power-on; the rpm field and the packets' timing follow, and below [`SPARSE_BELOW_RPM`] the
    /// unit sends every other packet.
    pub spin_up_s: Option<f64>,
    /// Amplitude of the slow rpm variation, rpm (the same quantity as `[sensors.lidar]
    /// rpm_wobble`, which it replaces when given).
    pub rpm_wobble: Option<f64>,
    /// The link goes silent at this simulated time (a USB adapter unplugged) …
    pub disconnect_at_s: Option<f64>,
    /// … and comes back this many seconds later (default: never).
    pub reconnect_after_s: Option<f64>,
}

/// The speed a spinning-up XV-11 first reports packets at: the real capture's lowest rpm field,
/// 49.8 (`hilsim decode tests/data/captures/xv11-hand-in-box.bin`).
pub const SPIN_UP_FROM_RPM: f64 = 50.0;

/// The faults in force, every value resolved.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinkFaults {
    /// See [`Link::corrupt_packet_rate`].
    pub corrupt_packet_rate: f64,
    /// See [`Link::dropped_byte_rate`].
    pub dropped_byte_rate: f64,
    /// See [`Link::dropped_packet_rate`].
    pub dropped_packet_rate: f64,
    /// See [`Link::spin_up_s`].
    pub spin_up_s: f64,
    /// See [`Link::rpm_wobble`]; `None`: the lidar's own.
    pub rpm_wobble: Option<f64>,
    /// The silent interval `[from, until)`, simulated seconds.
    pub silent: Option<(f64, f64)>,
}

/// Below this motor speed a spinning-up unit sends only every other packet: in the real capture
/// the first index gap comes at 206.8 rpm, and below it the indices jump by 44–46 (half a
/// revolution) from one packet to the next.
pub const SPARSE_BELOW_RPM: f64 = 210.0;

/// The profile fitted to the real capture in the repository (`tests/data/captures/
/// xv11-hand-in-box.bin`, 252,146 bytes, 11,451 packets; `hilsim decode … --json` and `--csv`):
/// - 1 packet of 11,451 fails its checksum: `corrupt_packet_rate` 8.7e-5;
/// - the first 10,827 packets come at 295–298 rpm with no index gap and no skipped byte: no
///   dropped bytes or packets (`dropped_byte_rate`, `dropped_packet_rate` 0);
/// - the last 608 come while the motor runs between 297 and 50 rpm, over about 3 s; below
///   [`SPARSE_BELOW_RPM`] the unit sends every other packet, which gives all 512 index gaps (and
///   the 224 skipped bytes): `spin_up_s` 3 (the same ramp at power-on, where a firmware meets
///   it), with the every-other-packet behaviour below 210 rpm.
pub const XV11_CAPTURE: LinkFaults = LinkFaults {
    corrupt_packet_rate: 1.0 / 11_451.0,
    dropped_byte_rate: 0.0,
    dropped_packet_rate: 0.0,
    spin_up_s: 3.0,
    rpm_wobble: None,
    silent: None,
};

impl Link {
    /// The faults in force: the profile's values, overridden by the keys given.
    ///
    /// # Errors
    /// An unknown profile, in words.
    pub fn faults(&self) -> Result<LinkFaults, String> {
        let base = match self.profile.as_deref() {
            None => LinkFaults::default(),
            Some("xv11-capture") => XV11_CAPTURE,
            Some(other) => {
                return Err(format!(
                    "unknown profile `{other}` (known: \"xv11-capture\")"
                ))
            }
        };
        let silent = self.disconnect_at_s.map(|from| {
            (
                from,
                self.reconnect_after_s.map_or(f64::INFINITY, |d| from + d),
            )
        });
        Ok(LinkFaults {
            corrupt_packet_rate: self.corrupt_packet_rate.unwrap_or(base.corrupt_packet_rate),
            dropped_byte_rate: self.dropped_byte_rate.unwrap_or(base.dropped_byte_rate),
            dropped_packet_rate: self.dropped_packet_rate.unwrap_or(base.dropped_packet_rate),
            spin_up_s: self.spin_up_s.unwrap_or(base.spin_up_s),
            rpm_wobble: self.rpm_wobble.or(base.rpm_wobble),
            silent: silent.or(base.silent),
        })
    }

    /// Checks every value: rates in [0, 0.5] (beyond, the stream is noise), times finite and
    /// non-negative, a reconnection only after a disconnection, and the rpm wobble smaller than
    /// the motor's speed: than the lidar's `rpm`, and during a spin-up than
    /// [`SPIN_UP_FROM_RPM`] (a wobble as large would stop the motor or turn it backwards).
    /// `lidar` is `[sensors.lidar]`'s `(rpm, rpm_wobble)`, when the scenario has one.
    ///
    /// # Errors
    /// The first bad key and why.
    pub fn validate(&self, lidar: Option<(f64, f64)>) -> Result<(), (&'static str, String)> {
        self.faults().map_err(|e| ("profile", e))?;
        for (key, value) in [
            ("corrupt_packet_rate", self.corrupt_packet_rate),
            ("dropped_byte_rate", self.dropped_byte_rate),
            ("dropped_packet_rate", self.dropped_packet_rate),
        ] {
            if let Some(v) = value {
                if !(v.is_finite() && (0.0..=0.5).contains(&v)) {
                    return Err((
                        key,
                        format!("expected a fraction in [0, 0.5], found {}", toml_number(v)),
                    ));
                }
            }
        }
        for (key, value) in [
            ("spin_up_s", self.spin_up_s),
            ("disconnect_at_s", self.disconnect_at_s),
            ("reconnect_after_s", self.reconnect_after_s),
        ] {
            if let Some(v) = value {
                if !(v.is_finite() && (0.0..=super::MAX_RUN_S).contains(&v)) {
                    return Err((
                        key,
                        format!(
                            "expected 0 to {} s, found {}",
                            super::MAX_RUN_S,
                            toml_number(v)
                        ),
                    ));
                }
            }
        }
        if let Some(v) = self.rpm_wobble {
            if !(v.is_finite() && v >= 0.0) {
                return Err((
                    "rpm_wobble",
                    format!("expected a number ≥ 0, found {}", toml_number(v)),
                ));
            }
            if let Some((rpm, _)) = lidar.filter(|&(rpm, _)| v >= rpm) {
                return Err((
                    "rpm_wobble",
                    format!(
                        "the wobble must be smaller than the rpm ([sensors.lidar] rpm = {}), \
                         found {}",
                        toml_number(rpm),
                        toml_number(v)
                    ),
                ));
            }
        }
        let faults = self.faults().map_err(|e| ("profile", e))?;
        if let Some((_, lidar_wobble)) = lidar {
            let wobble = faults.rpm_wobble.unwrap_or(lidar_wobble);
            if faults.spin_up_s > 0.0 && wobble >= SPIN_UP_FROM_RPM {
                let key = match (self.rpm_wobble, self.spin_up_s) {
                    (Some(_), _) => "rpm_wobble",
                    (None, Some(_)) => "spin_up_s",
                    (None, None) => "profile",
                };
                return Err((
                    key,
                    format!(
                        "a spin-up starts at {SPIN_UP_FROM_RPM} rpm, which a wobble of {} rpm \
                         would stop: keep the wobble below {SPIN_UP_FROM_RPM} rpm, or spin up \
                         in no time (`spin_up_s = 0`)",
                        toml_number(wobble)
                    ),
                ));
            }
        }
        if self.reconnect_after_s.is_some() && self.disconnect_at_s.is_none() {
            return Err((
                "reconnect_after_s",
                "a reconnection needs `disconnect_at_s`".into(),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_override_the_profile_and_nothing_is_on_by_default() {
        assert_eq!(Link::default().faults().unwrap(), LinkFaults::default());
        let link = Link {
            profile: Some("xv11-capture".into()),
            corrupt_packet_rate: Some(0.01),
            disconnect_at_s: Some(5.0),
            reconnect_after_s: Some(2.0),
            ..Link::default()
        };
        let f = link.faults().unwrap();
        assert_eq!(f.corrupt_packet_rate, 0.01);
        assert_eq!(f.spin_up_s, XV11_CAPTURE.spin_up_s);
        assert_eq!(f.silent, Some((5.0, 7.0)));
        let bad = Link {
            profile: Some("perfect".into()),
            ..Link::default()
        };
        assert!(bad.validate(None).is_err());
        let bad = Link {
            dropped_byte_rate: Some(0.9),
            ..Link::default()
        };
        assert_eq!(bad.validate(None).unwrap_err().0, "dropped_byte_rate");
    }

    #[test]
    fn the_rpm_wobble_must_stay_below_the_motor_speed() {
        let wobble = |v: f64| Link {
            rpm_wobble: Some(v),
            ..Link::default()
        };
        // `[sensors.lidar]` at 300 rpm with no wobble of its own.
        let lidar = Some((300.0, 0.0));
        assert_eq!(wobble(299.0).validate(lidar), Ok(()));
        for (v, found) in [(300.0, "300"), (20_000.0, "20000"), (1e300, "1e300")] {
            let (key, message) = wobble(v).validate(lidar).unwrap_err();
            assert_eq!(key, "rpm_wobble");
            assert_eq!(
                message,
                format!(
                    "the wobble must be smaller than the rpm ([sensors.lidar] rpm = 300), \
                     found {found}"
                )
            );
        }
        for (v, found) in [(-5.0, "-5"), (f64::NAN, "nan"), (f64::INFINITY, "inf")] {
            let message = wobble(v).validate(lidar).unwrap_err().1;
            assert_eq!(message, format!("expected a number ≥ 0, found {found}"));
        }
        // During a spin-up the motor starts at 50 rpm: a wobble as large, the link's or the
        // lidar's own, would stop it.
        let spin_up = Link {
            spin_up_s: Some(3.0),
            ..wobble(60.0)
        };
        let (key, message) = spin_up.validate(lidar).unwrap_err();
        assert_eq!(key, "rpm_wobble");
        assert!(
            message.contains("a wobble of 60 rpm would stop"),
            "{message}"
        );
        let profile = Link {
            profile: Some("xv11-capture".into()),
            ..Link::default()
        };
        assert_eq!(profile.validate(Some((300.0, 49.0))), Ok(()));
        assert_eq!(
            profile.validate(Some((300.0, 50.0))).unwrap_err().0,
            "profile"
        );
        let no_spin_up = Link {
            spin_up_s: Some(0.0),
            ..profile
        };
        assert_eq!(no_spin_up.validate(Some((300.0, 250.0))), Ok(()));
    }

    #[test]
    fn seconds_are_bounded_and_quoted_compactly() {
        let link = Link {
            spin_up_s: Some(1e300),
            ..Link::default()
        };
        assert_eq!(
            link.validate(None).unwrap_err(),
            (
                "spin_up_s",
                "expected 0 to 86400 s, found 1e300".to_string()
            )
        );
    }
}
