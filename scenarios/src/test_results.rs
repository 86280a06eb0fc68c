//! `hilsim scenario test`'s results and how they are shown: a line per scenario, one JSON
//! object, or JUnit XML for CI systems.

use std::io::{self, Write};

use hilsim_recording::FileKind;

use crate::Report;

/// How the JUnit file starts: the XML declaration and the suites' element with its name.
const JUNIT_START: &str =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"hilsim scenario test\"";

/// The JUnit file of [`TestResults::junit`], as a previous one is recognised.
pub const JUNIT_XML: FileKind = FileKind {
    name: "a JUnit XML file of hilsim scenario tests",
    starts_with: JUNIT_START.as_bytes(),
};

/// Each scenario's run, by the path it was read from, in the order given.
pub struct TestResults(pub Vec<(String, Report)>);

impl TestResults {
    /// Runs `scenarios` on `workers` threads, each named by its file; the results in the
    /// input order.
    ///
    /// # Errors
    /// The first scenario, in the input order, that could not be run to the end.
    pub fn execute(
        scenarios: Vec<(std::path::PathBuf, hilsim_sim::Scenario)>,
        workers: usize,
    ) -> Result<Self, crate::RunError> {
        let named: Vec<(String, hilsim_sim::Scenario)> = scenarios
            .into_iter()
            .map(|(path, s)| (path.display().to_string(), s))
            .collect();
        let reports = crate::execute_all(&named, workers);
        let results = named.iter().zip(reports);
        let results = results.map(|((path, _), report)| report.map(|r| (path.clone(), r)));
        results.collect::<Result<Vec<_>, _>>().map(Self)
    }

    /// The scenarios that failed an assertion.
    #[must_use]
    pub fn failed(&self) -> usize {
        self.0.iter().filter(|(_, r)| !r.passed()).count()
    }

    /// The scenarios that passed.
    #[must_use]
    pub fn passed(&self) -> usize {
        self.0.len() - self.failed()
    }

    /// `--json`: the counts and each scenario's assertions.
    #[must_use]
    pub fn to_json(&self) -> serde_json::Value {
        let scenarios: Vec<serde_json::Value> = self
            .0
            .iter()
            .map(|(path, r)| {
                serde_json::json!({
                    "scenario": r.scenario.name,
                    "path": path,
                    "passed": r.passed(),
                    "expectations": r.outcomes,
                })
            })
            .collect();
        serde_json::json!({
            "passed": self.passed(),
            "failed": self.failed(),
            "scenarios": scenarios,
        })
    }

    /// A line per scenario, each failed assertion under it, and the counts.
    ///
    /// # Errors
    /// Writing to `w` failed.
    pub fn write_text(&self, w: &mut dyn Write) -> io::Result<()> {
        let printable = hilsim_recording::printable;
        for (path, report) in &self.0 {
            writeln!(
                w,
                "{} {} ({}, {} assertion(s))",
                if report.passed() { "PASS" } else { "FAIL" },
                printable(&report.scenario.name),
                printable(path),
                report.outcomes.len()
            )?;
            for o in report.outcomes.iter().filter(|o| !o.passed) {
                writeln!(w, "    {}", o.describe())?;
            }
        }
        writeln!(w, "{} passed, {} failed", self.passed(), self.failed())
    }

    /// JUnit XML (the Ant schema CI systems read): a `testsuite` per scenario, a `testcase`
    /// per assertion, failed ones with a `failure`, skipped ones with `skipped`.
    #[must_use]
    pub fn junit(&self) -> String {
        let mut xml = String::from(JUNIT_START);
        let outcomes = || self.0.iter().flat_map(|(_, r)| &r.outcomes);
        let total = outcomes().count();
        let failures = outcomes().filter(|o| !o.passed).count();
        xml.push_str(&format!(" tests=\"{total}\" failures=\"{failures}\">\n"));
        for (path, report) in &self.0 {
            let failed = report.outcomes.iter().filter(|o| !o.passed).count();
            let skipped = report.outcomes.iter().filter(|o| o.skipped.is_some());
            let name = escape(&report.scenario.name);
            xml.push_str(&format!(
                "  <testsuite name=\"{name}\" tests=\"{}\" failures=\"{failed}\" skipped=\"{}\" \
                 file=\"{}\">\n",
                report.outcomes.len(),
                skipped.count(),
                escape(path)
            ));
            for o in &report.outcomes {
                xml.push_str(&format!(
                    "    <testcase classname=\"{name}\" name=\"{}\">",
                    escape(&o.metric)
                ));
                if let Some(why) = o.skipped {
                    xml.push_str(&format!("<skipped message=\"{}\"/>", escape(why)));
                } else if !o.passed {
                    xml.push_str(&format!("<failure message=\"{}\"/>", escape(&o.describe())));
                }
                xml.push_str("</testcase>\n");
            }
            xml.push_str("  </testsuite>\n");
        }
        xml.push_str("</testsuites>\n");
        xml
    }
}

/// Text as an XML attribute value.
fn escape(text: &str) -> String {
    text.chars()
        .map(|c| match c {
            '&' => "&amp;".to_string(),
            '<' => "&lt;".to_string(),
            '>' => "&gt;".to_string(),
            '"' => "&quot;".to_string(),
            '\'' => "&apos;".to_string(),
            c if (c as u32) < 0x20 && c != '\t' && c != '\n' => " ".to_string(),
            c => c.to_string(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::escape;

    #[test]
    fn escape_makes_any_text_an_attribute_value() {
        assert_eq!(escape("a<b & \"c\"\u{1}"), "a&lt;b &amp; &quot;c&quot; ");
    }
}
