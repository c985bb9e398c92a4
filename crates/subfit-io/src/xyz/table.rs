//! The values of a point list, row by row ([`Table`]): filled by the reader in [`crate::xyz`],
//! read by the column classification in `columns`.

/// Every point's values, row by row, with the line each came from.
pub(crate) struct Table {
    /// Values per point (the first point's count).
    pub(crate) cols: usize,
    /// `cols` values per point, row-major.
    pub(crate) values: Vec<f64>,
    /// The 1-based line of each point.
    pub(crate) lines: Vec<u64>,
}

impl Table {
    /// The number of points read.
    pub(crate) fn rows(&self) -> usize {
        self.lines.len()
    }

    /// The `cols` values of point `i`.
    pub(crate) fn row(&self, i: usize) -> &[f64] {
        &self.values[i * self.cols..(i + 1) * self.cols]
    }
}
