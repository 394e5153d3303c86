// An L-bracket, 80 x 40 mm legs of 6 mm plate, with a gusset between them.
union() {
    cube([80, 40, 6]);
    cube([6, 40, 70]);
    translate([6, 17, 6]) rotate([90, 0, 0]) rotate([0, 0, 0])
        linear_extrude(height = 6, center = true) polygon([[0, 0], [30, 0], [0, 30]]);
}
