// A hex nut, 60 mm across the corners and 30 mm high, with a 30 mm bore: flat faces around an
// axis of six-fold symmetry.
difference() {
    cylinder(d = 60, h = 30, $fn = 6);
    translate([0, 0, -1]) cylinder(d = 30, h = 32, $fn = 96);
}
