//! A pixel's 4-neighbours in a row-major image: the edge tests of the variance model, the
//! geometric edges and the shadow edges all compare a pixel with these.

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

#[cfg(test)]
mod tests {
    use super::*;

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
