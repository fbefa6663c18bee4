//! The CSV files of spectra/, embedded at build time so the binary needs no data directory.
//! Regenerate this list when a file is added to spectra/.

/// (file stem, file text) for every file in spectra/.
pub const EMBEDDED_SPECTRA: &[(&str, &str)] = &[
    ("A", include_str!("../../../spectra/A.csv")),
    ("D50", include_str!("../../../spectra/D50.csv")),
    ("D55", include_str!("../../../spectra/D55.csv")),
    ("D60", include_str!("../../../spectra/D60.csv")),
    ("D65", include_str!("../../../spectra/D65.csv")),
    ("D75", include_str!("../../../spectra/D75.csv")),
    ("E", include_str!("../../../spectra/E.csv")),
    ("F1", include_str!("../../../spectra/F1.csv")),
    ("F10", include_str!("../../../spectra/F10.csv")),
    ("F11", include_str!("../../../spectra/F11.csv")),
    ("F12", include_str!("../../../spectra/F12.csv")),
    ("F2", include_str!("../../../spectra/F2.csv")),
    ("F3", include_str!("../../../spectra/F3.csv")),
    ("F4", include_str!("../../../spectra/F4.csv")),
    ("F5", include_str!("../../../spectra/F5.csv")),
    ("F6", include_str!("../../../spectra/F6.csv")),
    ("F7", include_str!("../../../spectra/F7.csv")),
    ("F8", include_str!("../../../spectra/F8.csv")),
    ("F9", include_str!("../../../spectra/F9.csv")),
    ("LED-B1", include_str!("../../../spectra/LED-B1.csv")),
    ("LED-B2", include_str!("../../../spectra/LED-B2.csv")),
    ("LED-B3", include_str!("../../../spectra/LED-B3.csv")),
    ("LED-B4", include_str!("../../../spectra/LED-B4.csv")),
    ("LED-B5", include_str!("../../../spectra/LED-B5.csv")),
    ("LED-BH1", include_str!("../../../spectra/LED-BH1.csv")),
    ("LED-RGB1", include_str!("../../../spectra/LED-RGB1.csv")),
    ("LED-V1", include_str!("../../../spectra/LED-V1.csv")),
    ("LED-V2", include_str!("../../../spectra/LED-V2.csv")),
    (
        "cie-daylight-basis",
        include_str!("../../../spectra/cie-daylight-basis.csv"),
    ),
    (
        "cie1924-photopic",
        include_str!("../../../spectra/cie1924-photopic.csv"),
    ),
    (
        "cie1931-2deg",
        include_str!("../../../spectra/cie1931-2deg.csv"),
    ),
    (
        "cie1951-scotopic",
        include_str!("../../../spectra/cie1951-scotopic.csv"),
    ),
    (
        "cie1964-10deg",
        include_str!("../../../spectra/cie1964-10deg.csv"),
    ),
    (
        "colorchecker",
        include_str!("../../../spectra/colorchecker.csv"),
    ),
];
