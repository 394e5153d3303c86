// A 100 x 70 x 10 mm plate with four 10 mm holes and a 24 mm bore through it.
difference() {
    cube([100, 70, 10]);
    for (x = [15, 85], y = [15, 55]) translate([x, y, -1]) cylinder(d = 10, h = 12, $fn = 48);
    translate([50, 35, -1]) cylinder(d = 24, h = 12, $fn = 96);
}
