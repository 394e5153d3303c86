// A cone, 80 mm across its base and 90 mm high: a surface of revolution.
cylinder(r1 = 40, r2 = 0, h = 90, $fn = 128);
