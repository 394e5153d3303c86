// A stepped block: three steps, 80, 55 and 30 mm deep, 20 mm each, 50 mm wide.
union() {
    cube([80, 50, 20]);
    cube([55, 50, 40]);
    cube([30, 50, 60]);
}
