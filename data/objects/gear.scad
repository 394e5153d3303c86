// A spur gear: 24 teeth of module 3 (72 mm pitch circle), 20 mm thick, on a 16 mm bore.
teeth = 24;
m = 3;
r_pitch = m * teeth / 2;
r_root = r_pitch - 1.25 * m;
r_tip = r_pitch + m;
function tooth(k) = [
    for (a = [-0.30, -0.12, 0.12, 0.30]) let(r = abs(a) > 0.2 ? r_root : r_tip,
        t = (k + 0.5 + a) * 360 / teeth) [r * cos(t), r * sin(t)]
];
difference() {
    linear_extrude(height = 20) polygon([for (k = [0 : teeth - 1]) each tooth(k)]);
    translate([0, 0, -1]) cylinder(d = 16, h = 22, $fn = 48);
}
