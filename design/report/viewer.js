// The 3D view of a design in report.html (holofold.design.report.view): plain JavaScript, no library.
(function () {
  var root = document.getElementById(__ID__);
  var D = JSON.parse(root.querySelector("script[type='application/json']").textContent);
  var cv = root.querySelector("canvas"), ctx = cv.getContext("2d");
  var slider = root.querySelector("input[type=range]"), label = root.querySelector(".state");
  var K = D.frames.length, nv = D.frames[0].length;
  var yaw = -0.6, pitch = 0.45, zoom = 1.0, t = K - 1;
  slider.max = String(K - 1); slider.step = "0.01"; slider.value = String(K - 1);
  var lo = [1e30, 1e30, 1e30], hi = [-1e30, -1e30, -1e30];
  function grow(p) { for (var a = 0; a < 3; a++) { lo[a] = Math.min(lo[a], p[a]);
    hi[a] = Math.max(hi[a], p[a]); } }
  // the flat state is moved so that its centre sits on the folded state's centre
  var centres = D.frames.map(function (f) { var c = [0, 0, 0];
    f.forEach(function (p) { c[0] += p[0]; c[1] += p[1]; c[2] += p[2]; });
    return c.map(function (v) { return v / f.length; }); });
  var last = centres[K - 1];
  var frames = D.frames.map(function (f, k) { var c = centres[k];
    return f.map(function (p) { return [p[0] - c[0] + last[0], p[1] - c[1] + last[1],
      p[2] - c[2] + last[2]]; }); });
  frames.forEach(function (f) { f.forEach(grow); });
  if (D.curve) { D.curve.forEach(grow); }
  var centre = [0, 1, 2].map(function (a) { return 0.5 * (lo[a] + hi[a]); });
  var size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  var smin = 0, smax = 1;
  if (D.scalar) { smin = 1e30; smax = -1e30; D.scalar.forEach(function (row) {
    row.forEach(function (v) { smin = Math.min(smin, v); smax = Math.max(smax, v); }); });
    if (smax <= smin) { smax = smin + 1; } }
  function at(tt) {
    var k = Math.min(Math.floor(tt), K - 2), u = tt - k;
    if (K === 1) { return { X: frames[0], S: D.scalar ? D.scalar[0] : null }; }
    if (k < 0) { k = 0; u = 0; }
    var A = frames[k], B = frames[k + 1], X = new Array(nv), S = null;
    for (var i = 0; i < nv; i++) { X[i] = [A[i][0] + u * (B[i][0] - A[i][0]),
      A[i][1] + u * (B[i][1] - A[i][1]), A[i][2] + u * (B[i][2] - A[i][2])]; }
    if (D.scalar) { S = new Array(nv); for (var j = 0; j < nv; j++) {
      S[j] = D.scalar[k][j] + u * (D.scalar[k + 1][j] - D.scalar[k][j]); } }
    return { X: X, S: S };
  }
  function fitted(X) {  // the largest side of the state's box (and the curve's): it fills the view
    var a = [1e30, 1e30, 1e30], b = [-1e30, -1e30, -1e30];
    function g(p) { for (var i = 0; i < 3; i++) { a[i] = Math.min(a[i], p[i]); b[i] = Math.max(b[i], p[i]); } }
    X.forEach(g); if (D.curve) { D.curve.forEach(g); }
    return Math.max(b[0] - a[0], b[1] - a[1], b[2] - a[2]) || size;
  }
  function view(p) {  // z up; yaw about z, then pitch about the screen's x axis
    var x = p[0] - centre[0], y = p[1] - centre[1], z = p[2] - centre[2];
    var cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
    var x1 = cy * x - sy * y, y1 = sy * x + cy * y;
    return [x1, cp * z - sp * y1, sp * z + cp * y1];  // screen x, screen up, depth (away)
  }
  function colour(v) {  // blue - yellow - red
    var s = Math.max(0, Math.min(1, (v - smin) / (smax - smin)));
    var r = Math.round(255 * Math.min(1, 2 * s)), g = Math.round(200 * (1 - Math.abs(2 * s - 1)) + 40);
    var b = Math.round(255 * Math.max(0, 1 - 2 * s));
    return [r, g, b];
  }
  function draw() {
    var w = cv.clientWidth || 600, h = cv.clientHeight || 420, dpr = window.devicePixelRatio || 1;
    if (cv.width !== Math.round(w * dpr)) { cv.width = Math.round(w * dpr); cv.height = Math.round(h * dpr); }
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0); ctx.clearRect(0, 0, w, h);
    var st = at(t), P = st.X.map(view), sc = 0.8 * Math.min(w, h) / fitted(st.X) * zoom;
    function sx(p) { return w / 2 + sc * p[0]; } function sy(p) { return h / 2 - sc * p[1]; }
    var tris = D.triangles.map(function (tr) {
      var a = P[tr[0]], b = P[tr[1]], c = P[tr[2]];
      var ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
      var vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
      var nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
      var n = Math.sqrt(nx * nx + ny * ny + nz * nz) || 1;
      return { tr: tr, depth: (a[2] + b[2] + c[2]) / 3, light: Math.abs(0.35 * nx + 0.6 * ny - 0.72 * nz) / n,
               front: nz < 0 };
    });
    tris.sort(function (p, q) { return q.depth - p.depth; });
    tris.forEach(function (o) {
      var base = o.front ? [120, 160, 205] : [205, 185, 140];
      if (st.S) { base = colour((st.S[o.tr[0]] + st.S[o.tr[1]] + st.S[o.tr[2]]) / 3); }
      var f = 0.35 + 0.65 * o.light;
      ctx.fillStyle = "rgb(" + base.map(function (v) { return Math.round(v * f); }).join(",") + ")";
      ctx.strokeStyle = ctx.fillStyle; ctx.lineWidth = 0.5;
      ctx.beginPath(); ctx.moveTo(sx(P[o.tr[0]]), sy(P[o.tr[0]]));
      ctx.lineTo(sx(P[o.tr[1]]), sy(P[o.tr[1]])); ctx.lineTo(sx(P[o.tr[2]]), sy(P[o.tr[2]]));
      ctx.closePath(); ctx.fill(); ctx.stroke();
    });
    D.edges.forEach(function (e, k) {
      var kind = D.kinds.charAt(k);
      ctx.strokeStyle = kind === "M" ? "#c0392b" : kind === "V" ? "#1f5fa8" : kind === "B" ? "#333" : "#999";
      ctx.lineWidth = kind === "M" || kind === "V" ? 1.4 : 0.8;
      ctx.beginPath(); ctx.moveTo(sx(P[e[0]]), sy(P[e[0]])); ctx.lineTo(sx(P[e[1]]), sy(P[e[1]])); ctx.stroke();
    });
    if (D.curve) {
      ctx.strokeStyle = "#1e8c45"; ctx.lineWidth = 2; ctx.setLineDash([6, 4]); ctx.beginPath();
      D.curve.forEach(function (p, i) { var q = view(p); if (i) { ctx.lineTo(sx(q), sy(q)); } else { ctx.moveTo(sx(q), sy(q)); } });
      ctx.stroke(); ctx.setLineDash([]);
    }
    ctx.fillStyle = "#222";
    D.supports.forEach(function (v) { var x = sx(P[v]), y = sy(P[v]);
      ctx.beginPath(); ctx.moveTo(x, y); ctx.lineTo(x - 6, y + 10); ctx.lineTo(x + 6, y + 10); ctx.closePath(); ctx.fill(); });
    var named = {};
    D.loads.forEach(function (ld) {
      var d = ld.direction, n = Math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) || 1;
      var L = 0.15 * size, p = st.X[ld.vertex];
      var tail = view([p[0] - L * d[0] / n, p[1] - L * d[1] / n, p[2] - L * d[2] / n]), head = P[ld.vertex];
      var x0 = sx(tail), y0 = sy(tail), x1 = sx(head), y1 = sy(head), a = Math.atan2(y1 - y0, x1 - x0);
      ctx.strokeStyle = ctx.fillStyle = "#e67e22"; ctx.lineWidth = 2.5;
      ctx.beginPath(); ctx.moveTo(x0, y0); ctx.lineTo(x1, y1); ctx.stroke();
      ctx.beginPath(); ctx.moveTo(x1, y1); ctx.lineTo(x1 - 10 * Math.cos(a - 0.4), y1 - 10 * Math.sin(a - 0.4));
      ctx.lineTo(x1 - 10 * Math.cos(a + 0.4), y1 - 10 * Math.sin(a + 0.4)); ctx.closePath(); ctx.fill();
      if (ld.label && !named[ld.label]) { named[ld.label] = 1; ctx.font = "13px sans-serif";
        ctx.fillText(ld.label, x0 + 4, y0 - 4); }
    });
    if (D.scalar) {  // colour bar
      var bw = 140, bx = w - bw - 16, by = 14;
      for (var i = 0; i < bw; i++) { var c = colour(smin + (smax - smin) * i / (bw - 1));
        ctx.fillStyle = "rgb(" + c.join(",") + ")"; ctx.fillRect(bx + i, by, 1, 10); }
      ctx.fillStyle = "#222"; ctx.font = "12px sans-serif";
      ctx.fillText(smin.toFixed(0), bx, by + 24); ctx.fillText(smax.toFixed(0) + " " + D.scalar_unit, bx + bw - 48, by + 24);
      ctx.fillText(D.scalar_name, bx, by + 38);
    }
    var k = Math.round(t);
    label.textContent = Math.abs(t - k) < 0.01 ? D.labels[k] : "between " + D.labels[Math.floor(t)] + " and " + D.labels[Math.ceil(t)];
    root.dataset.viewerReady = "1"; root.dataset.viewerTriangles = String(tris.length);
    root.dataset.viewerState = String(t);
  }
  var drag = null;
  cv.addEventListener("pointerdown", function (e) { drag = [e.clientX, e.clientY]; cv.setPointerCapture(e.pointerId); });
  cv.addEventListener("pointerup", function () { drag = null; });
  cv.addEventListener("pointermove", function (e) { if (!drag) { return; }
    yaw += 0.01 * (e.clientX - drag[0]); pitch = Math.max(-1.55, Math.min(1.55, pitch + 0.01 * (e.clientY - drag[1])));
    drag = [e.clientX, e.clientY]; draw(); });
  cv.addEventListener("wheel", function (e) { e.preventDefault(); zoom *= e.deltaY < 0 ? 1.1 : 1 / 1.1; draw(); }, { passive: false });
  slider.addEventListener("input", function () { t = parseFloat(slider.value); draw(); });
  root.querySelectorAll("button[data-go]").forEach(function (b) { b.addEventListener("click", function () {
    var go = b.getAttribute("data-go");
    if (go === "play") { var t0 = null; t = 0; (function step(ts) { if (t0 === null) { t0 = ts; }
        t = Math.min(K - 1, (ts - t0) / 2500 * (K - 1)); slider.value = String(t); draw();
        if (t < K - 1) { window.requestAnimationFrame(step); } })(performance.now());
      return; }
    t = go === "flat" ? 0 : K - 1; slider.value = String(t); draw(); }); });
  root.viewer = { set: function (yw, pt, tt) { yaw = yw; pitch = pt; if (tt !== undefined) { t = tt; slider.value = String(tt); } draw(); } };
  window.addEventListener("resize", draw);
  draw();
})();
