//! NMEA 0183 sentences (the field layouts of NMEA 0183 versions 2.3 to 4.00, as its
//! sentence tables give them): the framing and checksum, the own ship's GPS fix (RMC, GGA, VTG) and true
//! heading (HDT), and a radar's tracked target (TTM).
//!
//! A sentence is `$` (or `!` for encapsulated data such as AIS), the talker and sentence
//! id, comma-separated fields, `*`, the checksum — the XOR of every byte between the start
//! character and `*`, as two upper-case hex digits — and CR LF.

use crate::error::{NmeaError, Result};

/// Metres in a nautical mile.
pub const NAUTICAL_MILE_M: f64 = 1852.0;

/// The checksum of a sentence's body (the bytes between the start character and `*`).
pub fn checksum(body: &str) -> u8 {
    body.bytes().fold(0, |c, b| c ^ b)
}

/// The whole sentence of `body` after the start character `start` (`$` or `!`): with its
/// checksum and CR LF.
pub fn frame(start: char, body: &str) -> String {
    format!("{start}{body}*{:02X}\r\n", checksum(body))
}

/// A UTC time of day and date.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UtcTime {
    /// Year.
    pub year: i64,
    /// Month, 1–12.
    pub month: u32,
    /// Day of the month, 1–31.
    pub day: u32,
    /// Hour, 0–23.
    pub hour: u32,
    /// Minute, 0–59.
    pub minute: u32,
    /// Second with its fraction, [0, 60).
    pub second: f64,
}

impl UtcTime {
    /// Seconds after 1970-01-01T00:00:00Z of a UTC time written `YYYY-MM-DDTHH:MM:SSZ`
    /// (whole seconds; None for anything else, or a date that does not exist).
    pub fn parse_unix_s(text: &str) -> Option<f64> {
        let t = text.trim().strip_suffix('Z')?;
        let (date, time) = t.split_once('T')?;
        let mut d = date.split('-').map(|x| x.parse::<i64>().ok());
        let (y, m, day) = (d.next()??, d.next()??, d.next()??);
        let mut h = time.split(':').map(|x| x.parse::<f64>().ok());
        let (hh, mm, ss) = (h.next()??, h.next()??, h.next()??);
        if d.next().is_some() || h.next().is_some() {
            return None;
        }
        let ok = (1..=12).contains(&m)
            && (1..=31).contains(&day)
            && (0.0..24.0).contains(&hh)
            && (0.0..60.0).contains(&mm)
            && (0.0..60.0).contains(&ss)
            && hh.fract() == 0.0
            && mm.fract() == 0.0
            && ss.fract() == 0.0;
        if !ok {
            return None;
        }
        // Days from 1970-01-01 of the proleptic Gregorian date (years counted from March).
        let (y, m) = if m <= 2 { (y - 1, m + 9) } else { (y, m - 3) };
        let era = y.div_euclid(400);
        let year_of_era = y.rem_euclid(400);
        let day_of_year = (153 * m + 2) / 5 + day - 1;
        let day_of_era = year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
        let days = era * 146_097 + day_of_era - 719_468;
        let unix_s = days as f64 * 86_400.0 + hh * 3600.0 + mm * 60.0 + ss;
        // A day past its month's end (2026-02-31) comes back as another date: refused.
        let back = UtcTime::from_unix_s(unix_s);
        let (year, month) = if m >= 10 { (y + 1, m - 9) } else { (y, m + 3) };
        (back.year == year && i64::from(back.month) == month && i64::from(back.day) == day)
            .then_some(unix_s)
    }

    /// The UTC time `unix_s` seconds after 1970-01-01T00:00:00Z (no leap seconds, as POSIX
    /// time counts). The date is the proleptic Gregorian calendar's.
    pub fn from_unix_s(unix_s: f64) -> UtcTime {
        let days = (unix_s / 86_400.0).floor();
        let in_day = unix_s - days * 86_400.0;
        let (year, month, day) = civil_date(days as i64);
        let hour = (in_day / 3600.0).floor();
        let minute = ((in_day - hour * 3600.0) / 60.0).floor();
        UtcTime {
            year,
            month,
            day,
            hour: hour as u32,
            minute: minute as u32,
            second: in_day - hour * 3600.0 - minute * 60.0,
        }
    }

    /// `hhmmss.ss`, the time field of RMC, GGA and TTM (the second rounded down to the
    /// hundredth, so a time never reads 60 s).
    pub fn time_field(&self) -> String {
        let hundredths = (self.second * 100.0).floor().min(5999.0) as u32;
        format!(
            "{:02}{:02}{:02}.{:02}",
            self.hour,
            self.minute,
            hundredths / 100,
            hundredths % 100
        )
    }

    /// `ddmmyy`, RMC's date field.
    pub fn date_field(&self) -> String {
        format!(
            "{:02}{:02}{:02}",
            self.day,
            self.month,
            self.year.rem_euclid(100)
        )
    }
}

/// The (year, month, day) of the day `days` after 1970-01-01 in the proleptic Gregorian
/// calendar: days counted into 400-year eras of 146 097 days that start on 1 March, so
/// that the leap day ends a year (the civil-from-days reckoning, H. Hinnant, "chrono-
/// Compatible Low-Level Date Algorithms", 2013).
fn civil_date(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468; // days from 0000-03-01
    let era = z.div_euclid(146_097);
    let day_of_era = z.rem_euclid(146_097);
    let year_of_era =
        (day_of_era - day_of_era / 1460 + day_of_era / 36_524 - day_of_era / 146_096) / 365;
    let day_of_year = day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
    let month_from_march = (5 * day_of_year + 2) / 153;
    let day = (day_of_year - (153 * month_from_march + 2) / 5 + 1) as u32;
    let month = if month_from_march < 10 {
        month_from_march + 3
    } else {
        month_from_march - 9
    } as u32;
    let year = year_of_era + era * 400 + i64::from(month <= 2);
    (year, month, day)
}

/// A latitude as `ddmm.mmmm` and its hemisphere (`N` or `S`), rounded to 10⁻⁴ minute
/// (0.19 m).
pub fn latitude_field(lat_deg: f64) -> Result<(String, char)> {
    if !(lat_deg.is_finite() && lat_deg.abs() <= 90.0) {
        return Err(NmeaError::field(
            "lat_deg",
            format!("{lat_deg}: must be within ±90°"),
        ));
    }
    let (text, _) = degrees_minutes(lat_deg.abs(), 2);
    Ok((text, if lat_deg < 0.0 { 'S' } else { 'N' }))
}

/// A longitude as `dddmm.mmmm` and its hemisphere (`E` or `W`), rounded to 10⁻⁴ minute.
pub fn longitude_field(lon_deg: f64) -> Result<(String, char)> {
    if !(lon_deg.is_finite() && lon_deg.abs() <= 180.0) {
        return Err(NmeaError::field(
            "lon_deg",
            format!("{lon_deg}: must be within ±180°"),
        ));
    }
    let (text, _) = degrees_minutes(lon_deg.abs(), 3);
    Ok((text, if lon_deg < 0.0 { 'W' } else { 'E' }))
}

/// `deg` (≥ 0) as whole degrees of `width` digits and minutes to 10⁻⁴, the rounding carried
/// into the degrees (59.99996′ reads 1°00.0000′, never 60′).
fn degrees_minutes(deg: f64, width: usize) -> (String, u64) {
    let ten_thousandths_of_minute = (deg * 600_000.0).round() as u64;
    let whole_deg = ten_thousandths_of_minute / 600_000;
    let rest = ten_thousandths_of_minute % 600_000;
    (
        format!(
            "{whole_deg:0width$}{:02}.{:04}",
            rest / 10_000,
            rest % 10_000
        ),
        ten_thousandths_of_minute,
    )
}

/// The own ship's navigation data at one moment, as its GPS and gyro compass give it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fix {
    /// When, s after 1970-01-01T00:00:00Z.
    pub unix_s: f64,
    /// Latitude, degrees (north positive).
    pub lat_deg: f64,
    /// Longitude, degrees (east positive).
    pub lon_deg: f64,
    /// The antenna's height above the sea, m (GGA's altitude; the geoid is taken as the sea).
    pub altitude_m: f64,
    /// Speed over ground, knots.
    pub sog_kn: f64,
    /// Course over ground, degrees true; `None` when it stands still (the field is empty).
    pub cog_deg: Option<f64>,
    /// True heading, degrees.
    pub heading_deg: f64,
}

/// A course or heading field, one decimal, in [0, 360).
fn angle_field(deg: f64) -> String {
    let tenths = (deg.rem_euclid(360.0) * 10.0).round() as u64 % 3600;
    format!("{}.{}", tenths / 10, tenths % 10)
}

/// `$--RMC`: recommended minimum data — time, status `A` (valid), position, speed and course
/// over ground, date, no magnetic variation, mode `A` (autonomous).
pub fn rmc(talker: &str, fix: &Fix) -> Result<String> {
    let t = UtcTime::from_unix_s(fix.unix_s);
    let (lat, ns) = latitude_field(fix.lat_deg)?;
    let (lon, ew) = longitude_field(fix.lon_deg)?;
    let cog = fix.cog_deg.map(angle_field).unwrap_or_default();
    Ok(frame(
        '$',
        &format!(
            "{talker}RMC,{},A,{lat},{ns},{lon},{ew},{:.1},{cog},{},,,A",
            t.time_field(),
            fix.sog_kn,
            t.date_field()
        ),
    ))
}

/// `$--GGA`: the fix — time, position, quality 1 (GPS fix), 8 satellites, HDOP 1.0, the
/// antenna's altitude, geoidal separation 0.
pub fn gga(talker: &str, fix: &Fix) -> Result<String> {
    let t = UtcTime::from_unix_s(fix.unix_s);
    let (lat, ns) = latitude_field(fix.lat_deg)?;
    let (lon, ew) = longitude_field(fix.lon_deg)?;
    Ok(frame(
        '$',
        &format!(
            "{talker}GGA,{},{lat},{ns},{lon},{ew},1,08,1.0,{:.1},M,0.0,M,,",
            t.time_field(),
            fix.altitude_m
        ),
    ))
}

/// `$--VTG`: course (true; magnetic left empty) and speed over ground in knots and km/h,
/// mode `A`.
pub fn vtg(talker: &str, fix: &Fix) -> String {
    let cog = fix.cog_deg.map(angle_field).unwrap_or_default();
    frame(
        '$',
        &format!(
            "{talker}VTG,{cog},T,,M,{:.1},N,{:.1},K,A",
            fix.sog_kn,
            fix.sog_kn * NAUTICAL_MILE_M / 1000.0
        ),
    )
}

/// `$--HDT`: true heading.
pub fn hdt(talker: &str, fix: &Fix) -> String {
    frame(
        '$',
        &format!("{talker}HDT,{},T", angle_field(fix.heading_deg)),
    )
}

/// A radar's tracked target, as TTM reports it (distances in nautical miles, speeds in
/// knots, true bearings and courses).
#[derive(Debug, Clone, PartialEq)]
pub struct TrackedTarget {
    /// Target number, 0–99 (the track's id modulo 100).
    pub number: u32,
    /// Distance from the own ship, m.
    pub distance_m: f64,
    /// Bearing from the own ship, degrees true.
    pub bearing_deg: f64,
    /// Speed, knots.
    pub speed_kn: f64,
    /// Course, degrees true; `None` below a speed that gives one (the field is empty).
    pub course_deg: Option<f64>,
    /// Distance of the closest point of approach, m.
    pub cpa_m: f64,
    /// Time to the closest point of approach, s (negative once past it); `None` with no
    /// relative motion (the field is empty).
    pub tcpa_s: Option<f64>,
    /// Its name (empty for none; commas and `*` are not allowed).
    pub name: String,
    /// `T` (tracking), `L` (lost) or `Q` (query: acquiring).
    pub status: char,
    /// When the data hold, s after 1970-01-01T00:00:00Z.
    pub unix_s: f64,
}

/// `$--TTM`: tracked target message — number, distance, bearing (T), speed, course (T), CPA,
/// TCPA (minutes), units `N`, name, status, no reference target, time, acquisition `A`
/// (automatic).
pub fn ttm(talker: &str, t: &TrackedTarget) -> Result<String> {
    if t.number > 99 {
        return Err(NmeaError::field(
            "number",
            format!("{}: a TTM target number is 0 to 99", t.number),
        ));
    }
    if t.name.contains([',', '*', '$', '!', '\r', '\n']) {
        return Err(NmeaError::field(
            "name",
            format!("{:?}: a name may not hold , * $ ! or a line break", t.name),
        ));
    }
    if !matches!(t.status, 'T' | 'L' | 'Q') {
        return Err(NmeaError::field(
            "status",
            format!("{:?}: must be T, L or Q", t.status),
        ));
    }
    let time = UtcTime::from_unix_s(t.unix_s);
    let course = t.course_deg.map(angle_field).unwrap_or_default();
    let tcpa = t
        .tcpa_s
        .map(|s| format!("{:.1}", s / 60.0))
        .unwrap_or_default();
    Ok(frame(
        '$',
        &format!(
            "{talker}TTM,{:02},{:.2},{},T,{:.1},{course},T,{:.2},{tcpa},N,{},{},,{},A",
            t.number,
            t.distance_m / NAUTICAL_MILE_M,
            angle_field(t.bearing_deg),
            t.speed_kn,
            t.cpa_m / NAUTICAL_MILE_M,
            t.name,
            t.status,
            time.time_field()
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// UTC times read as POSIX seconds (days from 1970-01-01 by the civil calendar), and
    /// impossible or malformed ones refused.
    #[test]
    fn utc_times_read_as_posix_seconds() {
        assert_eq!(UtcTime::parse_unix_s("1970-01-01T00:00:00Z"), Some(0.0));
        assert_eq!(
            UtcTime::parse_unix_s("2000-03-01T00:00:00Z"),
            Some(11_017.0 * 86_400.0)
        );
        assert_eq!(
            UtcTime::parse_unix_s("2026-12-07T12:34:56Z"),
            Some(20_794.0 * 86_400.0 + 45_296.0)
        );
        assert_eq!(UtcTime::parse_unix_s("2026-13-01T00:00:00Z"), None);
        assert_eq!(UtcTime::parse_unix_s("2026-02-31T00:00:00Z"), None);
        assert_eq!(
            UtcTime::parse_unix_s("2024-02-29T00:00:00Z"),
            Some(19_782.0 * 86_400.0)
        );
        assert_eq!(UtcTime::parse_unix_s("2026-01-01T00:00:00.5Z"), None);
        assert_eq!(UtcTime::parse_unix_s("2026-01-01 00:00:00"), None);
    }

    /// Checksums of sentences published with theirs: the GGA example of the NMEA reference
    /// pages (gpsd's "NMEA Revealed", `$GPGGA,092750.000,5321.6802,N,00630.3372,W,...*76`)
    /// and an RMC from a receiver log (`*6A`).
    #[test]
    fn checksums_match_published_sentences() {
        assert_eq!(
            checksum("GPGGA,092750.000,5321.6802,N,00630.3372,W,1,8,1.03,61.7,M,55.2,M,,"),
            0x76
        );
        assert_eq!(
            checksum("GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W"),
            0x6A
        );
        let s = frame('$', "HEHDT,274.1,T");
        assert!(s.starts_with("$HEHDT,274.1,T*") && s.ends_with("\r\n") && s.len() == 19);
    }

    /// Dates across leap years and the turn of centuries, against the day counts from the
    /// epoch (1972-02-29 is day 789; 2000-03-01 is day 11 017; 2026-12-07 is day 20 794).
    #[test]
    fn civil_dates_of_known_days() {
        assert_eq!(civil_date(0), (1970, 1, 1));
        assert_eq!(civil_date(789), (1972, 2, 29));
        assert_eq!(civil_date(11_016), (2000, 2, 29));
        assert_eq!(civil_date(11_017), (2000, 3, 1));
        assert_eq!(civil_date(20_794), (2026, 12, 7));
        assert_eq!(civil_date(-1), (1969, 12, 31));
        let t = UtcTime::from_unix_s(20_794.0 * 86_400.0 + 3600.0 * 13.0 + 60.0 * 5.0 + 7.256);
        assert_eq!((t.hour, t.minute), (13, 5));
        assert_eq!(t.time_field(), "130507.25");
        assert_eq!(t.date_field(), "071226");
    }

    /// Positions to 10⁻⁴ minute, with the hemisphere, and the rounding carried into the
    /// degrees.
    #[test]
    fn positions_are_degrees_and_minutes() {
        assert_eq!(
            latitude_field(53.361336).unwrap(),
            ("5321.6802".to_string(), 'N')
        );
        assert_eq!(
            longitude_field(-6.505620).unwrap(),
            ("00630.3372".to_string(), 'W')
        );
        assert_eq!(
            latitude_field(-10.999_999_99).unwrap(),
            ("1100.0000".to_string(), 'S')
        );
        let err = latitude_field(91.0).unwrap_err();
        assert!(err.to_string().starts_with("lat_deg: 91"), "{err}");
    }

    #[test]
    fn own_ship_sentences_carry_the_fix() {
        let fix = Fix {
            unix_s: 20_794.0 * 86_400.0 + 45_296.5,
            lat_deg: 50.365,
            lon_deg: -4.142,
            altitude_m: 12.0,
            sog_kn: 6.04,
            cog_deg: Some(359.97),
            heading_deg: 2.5,
        };
        let rmc = rmc("GP", &fix).unwrap();
        assert!(
            rmc.starts_with("$GPRMC,123456.50,A,5021.9000,N,00408.5200,W,6.0,0.0,071226,,,A*"),
            "{rmc}"
        );
        assert!(rmc.ends_with("\r\n"));
        let body = &rmc[1..rmc.len() - 5];
        assert_eq!(
            &rmc[rmc.len() - 4..rmc.len() - 2],
            format!("{:02X}", checksum(body))
        );
        let gga = gga("GP", &fix).unwrap();
        assert!(
            gga.starts_with("$GPGGA,123456.50,5021.9000,N,00408.5200,W,1,08,1.0,12.0,M,0.0,M,,*")
        );
        assert!(vtg("GP", &fix).starts_with("$GPVTG,0.0,T,,M,6.0,N,11.2,K,A*"));
        assert!(hdt("HE", &fix).starts_with("$HEHDT,2.5,T*"));
    }

    #[test]
    fn ttm_reports_a_track_and_refuses_what_it_cannot_carry() {
        let t = TrackedTarget {
            number: 7,
            distance_m: 1852.0 * 1.25,
            bearing_deg: 45.0,
            speed_kn: 12.0,
            course_deg: Some(270.0),
            cpa_m: 1852.0 * 0.1,
            tcpa_s: Some(300.0),
            name: "TRACK 7".into(),
            status: 'T',
            unix_s: 45_296.0,
        };
        let s = ttm("RA", &t).unwrap();
        assert!(
            s.starts_with("$RATTM,07,1.25,45.0,T,12.0,270.0,T,0.10,5.0,N,TRACK 7,T,,123456.00,A*"),
            "{s}"
        );
        let bad = TrackedTarget {
            number: 100,
            ..t.clone()
        };
        assert!(ttm("RA", &bad)
            .unwrap_err()
            .to_string()
            .starts_with("number: 100"));
        let bad = TrackedTarget {
            name: "A,B".into(),
            ..t
        };
        assert!(ttm("RA", &bad)
            .unwrap_err()
            .to_string()
            .starts_with("name:"));
    }
}
