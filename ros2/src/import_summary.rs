//! What a bag's import read, as `hilsim import` reports it.

use std::io::{self, Write};

use crate::ImportReport;

impl ImportReport {
    /// Each table's topic, its type and rows, then the notes.
    ///
    /// # Errors
    /// Writing to `w` failed.
    pub fn write_summary(&self, w: &mut dyn Write) -> io::Result<()> {
        for (role, (topic, kind)) in &self.chosen {
            let rows = self.rows.get(role).copied().unwrap_or(0);
            let topic = hilsim_recording::printable(topic);
            writeln!(w, "{role:<9} {topic} ({}): {rows} rows", kind.ros_name())?;
        }
        for note in &self.notes {
            writeln!(w, "note: {note}")?;
        }
        Ok(())
    }
}
