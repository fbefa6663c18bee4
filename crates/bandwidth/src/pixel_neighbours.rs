//! A pixel's neighbours in a row-major image: its 4-neighbours, which the edge tests of the
//! variance model, the geometric edges and the shadow edges compare it with, and the square
//! window around it that pooling sums, and that window's rings, which sparse probing searches
//! from the inside out.

use glam::UVec2;

/// The row-major indices of pixel `index`'s left, right, upper and lower neighbours that lie
/// inside `resolution`.
pub fn four_neighbours(index: usize, resolution: UVec2) -> impl Iterator<Item = usize> {
    let (w, h) = (resolution.x as usize, resolution.y as usize);
    let (x, y) = (index % w, index / w);
    [
        (x > 0).then(|| index - 1),
        (x + 1 < w).then(|| index + 1),
        (y > 0).then(|| index - w),
        (y + 1 < h).then(|| index + w),
    ]
    .into_iter()
    .flatten()
}

/// The (x, y) of the pixels within Chebyshev distance `radius` of (x, y), clipped at the
/// border of a `width` × `height` image, in row-major order (the pixel itself included).
pub fn window(
    (x, y): (usize, usize),
    radius: usize,
    (width, height): (usize, usize),
) -> impl Iterator<Item = (usize, usize)> {
    (y.saturating_sub(radius)..(y + radius + 1).min(height)).flat_map(move |yy| {
        (x.saturating_sub(radius)..(x + radius + 1).min(width)).map(move |xx| (xx, yy))
    })
}

/// The (x, y) of the pixels at Chebyshev distance exactly `distance` from (x, y), clipped
/// at the border of a `width` × `height` image: rings 0..=r cover [`window`] once each, so a
/// search for the nearest pixel can stop at the first ring past its best distance.
pub fn ring(
    (x, y): (usize, usize),
    distance: usize,
    (width, height): (usize, usize),
) -> impl Iterator<Item = (usize, usize)> {
    let d = distance;
    let columns = x.saturating_sub(d)..(x + d + 1).min(width);
    let top = (y >= d).then(|| y - d);
    let bottom = (d > 0 && y + d < height).then_some(y + d);
    let rows = [top, bottom]
        .into_iter()
        .flatten()
        .flat_map(move |yy| columns.clone().map(move |xx| (xx, yy)));
    // The sides, without the corners the rows hold (none at d = 0).
    let inner = (y + 1).saturating_sub(d)..(y + d).min(height);
    let left = (d > 0 && x >= d).then(|| x - d);
    let right = (d > 0 && x + d < width).then_some(x + d);
    let sides = [left, right]
        .into_iter()
        .flatten()
        .flat_map(move |xx| inner.clone().map(move |yy| (xx, yy)));
    rows.chain(sides)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rings 0..=r hold exactly the window's pixels, each once, at their own distance.
    #[test]
    fn rings_partition_the_window() {
        for (size, centre) in [
            ((7, 5), (3, 2)),
            ((7, 5), (0, 0)),
            ((4, 9), (3, 8)),
            ((1, 1), (0, 0)),
        ] {
            for r in 0..6 {
                let mut from_rings: Vec<(usize, usize)> = (0..=r)
                    .flat_map(|d| {
                        ring(centre, d, size).inspect(move |&(xx, yy)| {
                            assert_eq!(xx.abs_diff(centre.0).max(yy.abs_diff(centre.1)), d);
                        })
                    })
                    .collect();
                from_rings.sort_by_key(|&(xx, yy)| (yy, xx));
                let whole: Vec<_> = window(centre, r, size).collect();
                assert_eq!(from_rings, whole, "{size:?} {centre:?} r {r}");
            }
        }
    }

    #[test]
    fn a_window_is_clipped_at_the_border_in_row_major_order() {
        let corner: Vec<_> = window((0, 0), 1, (3, 3)).collect();
        assert_eq!(corner, vec![(0, 0), (1, 0), (0, 1), (1, 1)]);
        assert_eq!(window((1, 1), 1, (3, 3)).count(), 9);
        assert_eq!(window((2, 1), 0, (3, 3)).collect::<Vec<_>>(), vec![(2, 1)]);
    }

    #[test]
    fn corners_edges_and_the_inside_have_two_three_and_four() {
        let r = UVec2::new(3, 2);
        assert_eq!(four_neighbours(0, r).collect::<Vec<_>>(), vec![1, 3]);
        assert_eq!(four_neighbours(1, r).collect::<Vec<_>>(), vec![0, 2, 4]);
        assert_eq!(four_neighbours(5, r).collect::<Vec<_>>(), vec![4, 2]);
        let inside = UVec2::new(3, 3);
        assert_eq!(
            four_neighbours(4, inside).collect::<Vec<_>>(),
            vec![3, 5, 1, 7]
        );
    }
}
