// What the passes that keep a history across frames (the shadow filter's running mean,
// temporal anti-aliasing) agree a disocclusion is: one rule, so the shadows and the
// image forget the same pixels.

// The history is of the same surface if its distance from last frame's camera matches
// to 1%: the reprojected pixel lies within half a pixel of the surface's point, which
// on a plane at 80 degrees to the view moves the distance by a few thousandths a pixel.
const SAME_SURFACE: f32 = 0.01;

// Whether a history that saw its surface at `seen` (its distance from the camera then) is
// of the surface now at `expected` from that camera, where the history's sample may lie
// up to `slack` further or nearer along the surface (a history read a sub-pixel away from
// the point: temporal anti-aliasing's jittered samples; 0 where it is read at the point).
fn same_surface(seen: f32, expected: f32, slack: f32) -> bool {
    return abs(seen - expected) <= SAME_SURFACE * expected + slack;
}
