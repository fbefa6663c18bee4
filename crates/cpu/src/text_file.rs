//! Reading a user's text file (scene JSON, spectrum CSV, OBJ, BFC-450, IES tilt, phase
//! tables) with messages in the project's words: a folder given for a file says so, bytes
//! that are not UTF-8 are located (byte offset, line and column), and a UTF-8 byte-order
//! mark, which editors on Windows write and JSON parsers reject as "expected value", is
//! skipped. It lives in prism-cpu, the crate every other one may depend on.

use std::path::Path;

/// The UTF-8 encoding of U+FEFF, the byte-order mark.
const BOM: &str = "\u{feff}";

/// Reads `path` as UTF-8 text without a leading byte-order mark. The error is a sentence
/// without the file name (callers put it in their own positioned error).
pub fn read_text(path: &Path) -> Result<String, String> {
    if path.is_dir() {
        return Err("it is a directory; expected a file".to_string());
    }
    let bytes = std::fs::read(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        _ => format!("cannot read it ({e})"),
    })?;
    let mut text = String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let before = &e.as_bytes()[..offset];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |p| p + 1);
        // Valid UTF-8 up to `offset`: count characters for the column.
        let column =
            std::str::from_utf8(&before[line_start..]).map_or(0, |s| s.chars().count()) + 1;
        format!(
            "byte {offset} (line {line}, column {column}) is not UTF-8 text (0x{:02x}); \
             expected a UTF-8 text file",
            e.as_bytes()[offset]
        )
    })?;
    if text.starts_with(BOM) {
        text.drain(..BOM.len());
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_files_are_read_with_positioned_errors() {
        let temp = tempfile::tempdir().unwrap();
        let dir = temp.path().to_path_buf();
        let bom = dir.join("bom.json");
        std::fs::write(&bom, "\u{feff}{\"a\": 1}").unwrap();
        assert_eq!(read_text(&bom).unwrap(), "{\"a\": 1}");
        let latin1 = dir.join("latin1.csv");
        std::fs::write(&latin1, b"nm,v\n500,caf\xe9\n").unwrap();
        let e = read_text(&latin1).unwrap_err();
        assert!(
            e.contains("byte 12 (line 2, column 8)") && e.contains("0xe9"),
            "{e}"
        );
        assert!(read_text(&dir).unwrap_err().contains("is a directory"));
        assert_eq!(read_text(&dir.join("none")).unwrap_err(), "no such file");
    }
}
