//! Warnings about the files a command loads, printed the same way by every
//! command.

/// Most warnings printed one by one; the rest are counted.
const MAX_WARNINGS_SHOWN: usize = 20;

/// Prints warnings to stderr (the first [`MAX_WARNINGS_SHOWN`]) and their count.
pub fn print(warnings: &[String]) {
    for w in warnings.iter().take(MAX_WARNINGS_SHOWN) {
        eprintln!("warning: {w}");
    }
    if warnings.len() > MAX_WARNINGS_SHOWN {
        eprintln!("... and {} more", warnings.len() - MAX_WARNINGS_SHOWN);
    }
    if !warnings.is_empty() {
        eprintln!(
            "{} warning{} while loading",
            warnings.len(),
            if warnings.len() == 1 { "" } else { "s" }
        );
    }
}
