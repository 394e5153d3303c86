// A long thin box, 120 x 20 x 15 mm, lying flat: little surface seen from the sides.
cube([120, 20, 15]);
