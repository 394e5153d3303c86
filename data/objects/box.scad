// A plain box, 60 x 40 x 80 mm: flat faces at right angles (make measure-objects).
cube([60, 40, 80]);
