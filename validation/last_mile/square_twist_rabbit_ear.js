// Square twist drawn in Rabbit Ear from the segments of Origami Simulator's singlesquaretwist.svg
// Usage: NODE_PATH=~/.cache/holofold-node/node_modules node square_twist_rabbit_ear.js \
//   /work/os-examples/assets/Origami/singlesquaretwist.svg square_twist.fold
// (Rabbit Ear 0.9.32 has no SVG reader: the SVG's M/l segments are parsed here, coloured
// blue = valley, red = mountain, black = boundary, as Origami Simulator draws them.)
const ear = require("rabbit-ear");
const fs = require("fs");
const svg = fs.readFileSync(process.argv[2], "utf8");
const colour = { "#0000FF": "V", "#FF0000": "M", "#000000": "B" };
const coords = [], edges = [], assign = [];
// the drawing rounds to 0.01 px: endpoints within 0.1 px are one vertex
const snap = (p) => {
  const i = coords.findIndex((q) => Math.hypot(q[0] - p[0], q[1] - p[1]) < 0.1);
  if (i >= 0) return i;
  coords.push(p);
  return coords.length - 1;
};
for (const m of svg.matchAll(/stroke="(#[0-9A-F]{6})"[^>]*?d="([^"]*)"/g)) {
  const a = colour[m[1]];
  for (const seg of m[2].matchAll(/M\s*(-?[\d.]+)\s*,\s*(-?[\d.]+)\s*l\s*(-?[\d.]+)\s*,?\s*(-?[\d.]+)/g)) {
    const [x, y, dx, dy] = seg.slice(1).map(Number);
    edges.push([snap([x, y]), snap([x + dx, y + dy])]);
    assign.push(a);
  }
}
const g = { vertices_coords: coords, edges_vertices: edges, edges_assignment: assign };
const out = JSON.parse(JSON.stringify(g));
ear.graph.fragment(out, 1e-6);  // split any crossing
const fold = {
  file_spec: 1.1,
  file_creator: "Rabbit Ear 0.9.32 (ear.graph.fragment, populate), from Origami Simulator's singlesquaretwist.svg",
  file_classes: ["singleModel"],
  frame_classes: ["creasePattern"],
  vertices_coords: out.vertices_coords,
  edges_vertices: out.edges_vertices,
  edges_assignment: out.edges_assignment,
};
const f2 = ear.graph.populate(JSON.parse(JSON.stringify(fold)));
fold.faces_vertices = f2.faces_vertices;
fs.writeFileSync(process.argv[3], JSON.stringify(fold, null, 1));
console.error("vertices", fold.vertices_coords.length, "edges", fold.edges_vertices.length, "faces", (fold.faces_vertices||[]).length, "valid", JSON.stringify(ear.graph.validate(f2)).slice(0,200));
