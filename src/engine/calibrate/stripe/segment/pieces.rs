//! The profile as the arc search sees it: points in order, the pitch
//! between neighbours, and contiguous pieces along the profile.

use super::{Circle, OPEN_PIECES};

/// A piece of consensus: consecutive band points along the profile, each
/// within the gap limit of the one before it in the piece.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Piece {
    /// Band points in the piece.
    pub(super) count: usize,
    /// Index of its first point in the profile.
    pub(super) first: usize,
    /// Index of its last point in the profile.
    pub(super) last: usize,
    /// Band points in the piece that the previous round kept.
    pub(super) common: usize,
}

/// Splits the band points of a circle, met in profile order, into pieces
/// (method step 1): a point continues the most recently extended of the
/// last [`OPEN_PIECES`] pieces whose last point is within the gap limit,
/// else it starts a new piece. A stray band point elsewhere on the circle
/// (clutter on its far side) thus starts a piece of its own without cutting
/// the arc in two.
pub(super) struct Pieces {
    #[allow(
        clippy::struct_field_names,
        reason = "the pieces themselves, beside the open ones"
    )]
    pub(super) pieces: Vec<Piece>,
    /// Ids of the open pieces, most recently extended first.
    pub(super) open: Vec<usize>,
    pub(super) max_gap2: f64,
}

impl Pieces {
    pub(super) fn new(max_gap2: f64) -> Self {
        Self {
            pieces: Vec::new(),
            open: Vec::with_capacity(OPEN_PIECES + 1),
            max_gap2,
        }
    }

    /// Adds band point `i` (`common`: the previous round kept it); returns
    /// the id of its piece.
    pub(super) fn push(&mut self, points: &[[f64; 2]], i: usize, common: bool) -> usize {
        let p = &points[i];
        let found = self.open.iter().position(|&id| {
            let q = &points[self.pieces[id].last];
            let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
            dx * dx + dy * dy <= self.max_gap2
        });
        let id = if let Some(pos) = found {
            let id = self.open.remove(pos);
            let piece = &mut self.pieces[id];
            piece.count += 1;
            piece.last = i;
            id
        } else {
            self.pieces.push(Piece {
                count: 1,
                first: i,
                last: i,
                common: 0,
            });
            self.open.truncate(OPEN_PIECES - 1);
            self.pieces.len() - 1
        };
        self.pieces[id].common += usize::from(common);
        self.open.insert(0, id);
        id
    }

    /// The piece with the most points the previous round kept, then with the
    /// most points (the first such on a tie); `None` when there is none.
    pub(super) fn best(&self) -> Option<(usize, Piece)> {
        let mut best: Option<(usize, Piece)> = None;
        for (id, piece) in self.pieces.iter().enumerate() {
            if best.is_none_or(|(_, b)| (piece.common, piece.count) > (b.common, b.count)) {
                best = Some((id, *piece));
            }
        }
        best
    }
}

/// What the search works with.
pub(super) struct Profile<'a> {
    pub(super) points: &'a [[f64; 2]],
    /// Squared largest gap between consecutive arc points, mm².
    pub(super) max_gap2: f64,
}

impl Profile<'_> {
    /// The largest piece of the points within `band` of `circle`, over the
    /// points `step` apart, with the gap limit `max_gap2` (mm²).
    pub(super) fn score(&self, circle: &Circle, band: f64, step: usize, max_gap2: f64) -> Piece {
        let limits = circle.band_limits(band);
        let mut pieces = Pieces::new(max_gap2);
        for (i, p) in self.points.iter().enumerate().step_by(step) {
            if circle.within(p, limits) {
                pieces.push(self.points, i, false);
            }
        }
        pieces.best().map(|(_, p)| p).unwrap_or_default()
    }

    /// The points within `band` of `circle` in the piece with the most
    /// points of `previous` (a mask over the profile), or, without one or on
    /// a tie, with the most points; ascending.
    pub(super) fn collect(
        &self,
        circle: &Circle,
        band: f64,
        previous: Option<&[bool]>,
    ) -> Vec<usize> {
        let limits = circle.band_limits(band);
        let mut pieces = Pieces::new(self.max_gap2);
        let mut members: Vec<(usize, usize)> = Vec::new();
        for (i, p) in self.points.iter().enumerate() {
            if circle.within(p, limits) {
                let common = previous.is_some_and(|m| m.get(i).copied().unwrap_or(false));
                members.push((i, pieces.push(self.points, i, common)));
            }
        }
        let Some((best, _)) = pieces.best() else {
            return Vec::new();
        };
        members
            .into_iter()
            .filter(|&(_, id)| id == best)
            .map(|(i, _)| i)
            .collect()
    }
}
