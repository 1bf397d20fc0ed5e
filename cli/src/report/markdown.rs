//! Markdown pieces: tables and numbers written so that every figure in the report is a
//! finite number or an explicit dash.

/// A Markdown table from a header and rows of cells.
pub fn table(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut s = format!(
        "| {} |\n|{}\n",
        header.join(" | "),
        "---|".repeat(header.len())
    );
    for r in rows {
        s += &format!("| {} |\n", r.join(" | "));
    }
    s
}

/// `v` with `digits` significant digits; a dash where it is not a finite number.
pub fn num(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return "–".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let magnitude = v.abs().log10().floor() as i32;
    if (-3..6).contains(&magnitude) {
        let decimals = (digits as i32 - 1 - magnitude).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{:.*e}", digits.saturating_sub(1), v)
    }
}

/// An image link with its caption under it.
pub fn figure(file: &str, alt: &str, caption: &str) -> String {
    format!("![{alt}]({file})\n\n*{caption}*\n\n")
}
