//! A pixel's neighbours in a row-major image: its 4-neighbours, which the edge tests of the
//! variance model, the geometric edges and the shadow edges compare it with, and the square
//! window around it that pooling and sparse probing search.

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

#[cfg(test)]
mod tests {
    use super::*;

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
