// A thin-walled cup: 70 mm across, 2.5 mm walls, 90 mm high, open at the top.
difference() {
    cylinder(r = 35, h = 90, $fn = 128);
    translate([0, 0, 3]) cylinder(r = 32.5, h = 90, $fn = 128);
}
