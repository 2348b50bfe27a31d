// 3-D views of report.html on a 2-D canvas: depth-sorted flat-shaded triangles and lines
// (painter's algorithm), no WebGL and no network. Drag: rotate, wheel: zoom, shift-drag: pan,
// click: pick an element. Scenes come from tmfem.post.html_report (base64 float32 arrays).
(function () {
  "use strict";
  function decode(s, T) {
    var bin = atob(s), u8 = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) u8[i] = bin.charCodeAt(i);
    return new T(u8.buffer);
  }
  var VIRIDIS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
  var COOLWARM = [[59, 76, 192], [141, 176, 254], [221, 221, 221], [244, 154, 123], [180, 4, 38]];
  function colour(stops, t) {
    t = isFinite(t) ? Math.min(1, Math.max(0, t)) : 0;
    var x = t * (stops.length - 1), i = Math.min(stops.length - 2, Math.floor(x)), f = x - i;
    var a = stops[i], b = stops[i + 1];
    return [a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f];
  }
  function rgb(c, k) {
    k = k === undefined ? 1 : k;
    return "rgb(" + Math.round(c[0] * k) + "," + Math.round(c[1] * k) + "," + Math.round(c[2] * k) + ")";
  }
  function range(a) {
    var lo = Infinity, hi = -Infinity;
    for (var i = 0; i < a.length; i++) { if (a[i] < lo) lo = a[i]; if (a[i] > hi) hi = a[i]; }
    if (!isFinite(lo)) { lo = 0; hi = 1; }
    if (hi - lo < 1e-12 * Math.max(1, Math.abs(hi))) hi = lo + 1;
    return [lo, hi];
  }
  // colour range of a stress field: its minimum to its 98th percentile (the corner peaks of a
  // point-attached membrane would leave the rest in one colour); clipped values show the top colour
  function robust(a) {
    var s = Array.prototype.slice.call(a).sort(function (x, y) { return x - y; });
    var r = range(a), hi = s[Math.floor(0.98 * (s.length - 1))];
    return hi > r[0] && hi < r[1] ? [r[0], hi, true] : [r[0], r[1], false];
  }
  function absmax(a) { var m = 0; for (var i = 0; i < a.length; i++) if (isFinite(a[i])) m = Math.max(m, Math.abs(a[i])); return m; }
  function fmt(v) { return Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-2 && v !== 0) ? v.toExponential(2) : v.toPrecision(3); }
  function el(tag, attrs, parent) {
    var e = document.createElement(tag);
    for (var k in attrs) { if (k === "text") e.textContent = attrs[k]; else e.setAttribute(k, attrs[k]); }
    if (parent) parent.appendChild(e);
    return e;
  }

  function Viewer(root, scene) {
    this.root = root; this.scene = scene;
    this.canvas = root.querySelector("canvas");
    this.ctx = this.canvas.getContext("2d");
    this.info = root.querySelector(".info");
    this.controls = root.querySelector(".controls");
    this.yaw = -0.7; this.pitch = 0.45; this.zoom = 1; this.pan = [0, 0];
    this.frame = 0; this.phase = 1;
    var geo = scene.type === "configuration" ? scene.sets[0] : scene;
    this.setGeometry(geo);
    this["setup_" + scene.type]();
    this.bindMouse();
    this.ready = true;
    var self = this;
    window.addEventListener("resize", function () { self.draw(); });
    this.draw();
    root.dataset.ready = "1";
  }
  Viewer.prototype.setGeometry = function (g) {
    this.base = decode(g.points, Float32Array);
    this.lines = decode(g.lines, Int32Array);
    this.lineKind = decode(g.line_kind, Uint8Array);
    this.tris = decode(g.tris, Int32Array);
    var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (var i = 0; i < this.base.length; i += 3)
      for (var c = 0; c < 3; c++) { lo[c] = Math.min(lo[c], this.base[i + c]); hi[c] = Math.max(hi[c], this.base[i + c]); }
    this.center = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2];
    this.size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  };
  Viewer.prototype.addSelect = function (label, options, onchange) {
    var l = el("label", {text: label + " "}, this.controls), s = el("select", {}, l);
    options.forEach(function (o, i) { el("option", {value: i, text: o}, s); });
    s.addEventListener("change", function () { onchange(+s.value); });
    return s;
  };
  Viewer.prototype.addRange = function (label, min, max, step, value, oninput) {
    var l = el("label", {text: label + " "}, this.controls);
    var r = el("input", {type: "range", min: min, max: max, step: step, value: value}, l);
    var out = el("span", {"class": "value"}, l);
    r.addEventListener("input", function () { out.textContent = oninput(+r.value); });
    out.textContent = oninput(+r.value, true);
    return r;
  };
  Viewer.prototype.addButton = function (label, onclick) {
    var b = el("button", {type: "button", text: label}, this.controls);
    b.addEventListener("click", function () { onclick(b); });
    return b;
  };
  Viewer.prototype.animate = function (step) {
    var self = this, last = null;
    function tick(ts) {
      if (!self.running) return;
      if (last !== null) step((ts - last) / 1000);
      last = ts;
      self.draw();
      requestAnimationFrame(tick);
    }
    requestAnimationFrame(tick);
  };

  // --- configurations: data set, membrane field; lines coloured by axial force
  Viewer.prototype.setup_configuration = function () {
    var self = this, sc = this.scene;
    this.set = 0;
    function load(i) {
      self.set = i;
      var g = sc.sets[i];
      self.setGeometry(g);
      self.fieldKeys = g.tri_fields.map(function (f, i) { return i; });
      self.triFields = g.tri_fields.map(function (f) { var v = decode(f.data, Float32Array); return {values: v, range: robust(v)}; });
      self.lineForce = g.line_field ? decode(g.line_field.data, Float32Array) : null;
      self.field = Math.min(self.field || 0, self.fieldKeys.length - 1);
    }
    load(0);
    if (sc.sets.length > 1)
      this.addSelect("configuration", sc.sets.map(function (s) { return s.label; }), function (i) { load(i); self.draw(); });
    var g0 = sc.sets[0];
    if (g0.tri_fields.length)
      this.addSelect("membrane", g0.tri_fields.map(function (f) { return f.title; }),
        function (i) { self.field = i; self.draw(); });
    this.positions = function () { return self.base; };
    this.triColour = function () {
      if (!self.fieldKeys.length) return null;
      var f = sc.sets[self.set].tri_fields[self.field], v = self.triFields[self.field];
      return {values: v.values, lo: v.range[0], hi: v.range[1], stops: VIRIDIS, clipped: v.range[2],
              title: f.title + " [" + f.unit + "]"};
    };
    this.lineColour = function () { return self.forceColour(self.lineForce); };
  };
  Viewer.prototype.forceColour = function (f) {
    if (!f) return null;
    var r = range(f), m = Math.max(Math.abs(r[0]), Math.abs(r[1]));
    return {values: f, lo: -m, hi: m, stops: COOLWARM, title: "axial force [N] (tension > 0)"};
  };

  // --- mode shapes: selector, amplitude, oscillation
  Viewer.prototype.setup_modes = function () {
    var self = this, sc = this.scene;
    this.shapes = sc.modes.map(function (m) { return decode(m.shape, Float32Array); });
    this.modeFields = sc.modes.map(function (m) { return decode(m.tri_field, Float32Array); });
    this.mode = 0; this.amp = sc.amplitude;
    this.addSelect("mode", sc.modes.map(function (m) { return m.label; }), function (i) { self.mode = i; self.draw(); });
    this.addRange("amplitude", 0, 0.3, 0.01, sc.amplitude, function (v) {
      self.amp = v; if (!self.running) self.draw();
      return "largest displacement " + Math.round(100 * v) + " % of the system's size";
    });
    var t = 0;
    this.addButton("oscillate", function (b) {
      self.running = !self.running; b.textContent = self.running ? "stop" : "oscillate";
      if (self.running) self.animate(function (dt) { t += dt; self.phase = Math.cos(2 * Math.PI * t / 1.5); });
      else { self.phase = 1; self.draw(); }
    });
    var buf = new Float32Array(this.base.length);
    this.positions = function () {
      var s = self.shapes[self.mode], a = self.amp * self.phase;
      for (var i = 0; i < buf.length; i++) buf[i] = self.base[i] + a * s[i];
      return buf;
    };
    this.triColour = function () {
      return {values: self.modeFields[self.mode], lo: 0, hi: 1, stops: VIRIDIS,
              title: "|displacement| of the mode / its largest [-]"};
    };
    this.lineColour = function () { return null; };
  };

  // --- time series: time slider, playback, membrane deflection drawn enlarged
  Viewer.prototype.setup_series = function () {
    var self = this, sc = this.scene, n = sc.n_points, nf = sc.n_frames;
    this.frames = decode(sc.frames, Float32Array);
    this.w = decode(sc.w, Float32Array);
    this.normals = decode(sc.normals, Float32Array);
    this.force = decode(sc.line_force, Float32Array);
    this.scale = sc.deflection_scale;
    // the view opens at the frame of the largest membrane deflection
    var first = 0, big = -1;
    for (var f = 0; f < nf; f++) { var m = absmax(this.w.subarray(n * f, n * (f + 1))); if (m > big) { big = m; first = f; } }
    var slider = this.addRange("t", 0, nf - 1, 1, first, function (v) {
      self.frame = v; if (!self.running) self.draw();
      return sc.times[v].toFixed(2) + " s";
    });
    var acc = 0;
    this.addButton("play", function (b) {
      self.running = !self.running; b.textContent = self.running ? "pause" : "play";
      if (self.running) self.animate(function (dt) {
        acc += dt;
        if (acc > 0.12) { acc = 0; slider.value = (+slider.value + 1) % nf; slider.dispatchEvent(new Event("input")); }
      });
    });
    if (sc.has_membrane && sc.w_max_mm > 0)
      this.addRange("membrane deflection x", 1, 5 * sc.deflection_scale, 1, sc.deflection_scale, function (v) {
        self.scale = v; if (!self.running) self.draw();
        return String(v);
      });
    var buf = new Float32Array(3 * n), wm = absmax(this.w);
    this.positions = function () {
      var f = self.frame, X = self.frames.subarray(3 * n * f, 3 * n * (f + 1)), w = self.w.subarray(n * f, n * (f + 1));
      var nx = self.normals[3 * f], ny = self.normals[3 * f + 1], nz = self.normals[3 * f + 2], k = (self.scale - 1) / 1000;
      for (var i = 0; i < n; i++) {
        buf[3 * i] = X[3 * i] + k * w[i] * nx; buf[3 * i + 1] = X[3 * i + 1] + k * w[i] * ny; buf[3 * i + 2] = X[3 * i + 2] + k * w[i] * nz;
      }
      return buf;
    };
    var tv = new Float32Array(this.tris.length / 3);
    this.triColour = function () {
      if (!sc.has_membrane || !(wm > 0)) return null;
      var w = self.w.subarray(n * self.frame, n * (self.frame + 1)), T = self.tris;
      for (var j = 0; j < tv.length; j++) tv[j] = (w[T[3 * j]] + w[T[3 * j + 1]] + w[T[3 * j + 2]]) / 3;
      return {values: tv, lo: -wm, hi: wm, stops: COOLWARM, title: "membrane deflection w in O_f [mm]"};
    };
    var nl = this.lines.length / 2, fm = absmax(this.force);
    this.lineColour = function () {
      if (!(fm > 0)) return null;
      return {values: self.force.subarray(nl * self.frame, nl * (self.frame + 1)), lo: -fm, hi: fm,
              stops: COOLWARM, title: "axial force [N] (tension > 0)"};
    };
  };

  Viewer.prototype.bindMouse = function () {
    var self = this, c = this.canvas, drag = null;
    c.addEventListener("mousedown", function (e) { drag = {x: e.clientX, y: e.clientY, moved: false, pan: e.shiftKey}; });
    window.addEventListener("mouseup", function (e) {
      if (drag && !drag.moved) self.pick(e);
      drag = null;
    });
    window.addEventListener("mousemove", function (e) {
      if (!drag) return;
      var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      if (Math.abs(dx) + Math.abs(dy) > 2) drag.moved = true;
      drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) { self.pan[0] += dx; self.pan[1] += dy; }
      else { self.yaw += 0.01 * dx; self.pitch = Math.max(-1.55, Math.min(1.55, self.pitch + 0.01 * dy)); }
      self.draw();
    });
    c.addEventListener("wheel", function (e) {
      e.preventDefault();
      self.zoom *= Math.exp(-0.0015 * e.deltaY);
      self.draw();
    }, {passive: false});
    c.addEventListener("dblclick", function () { self.yaw = -0.7; self.pitch = 0.45; self.zoom = 1; self.pan = [0, 0]; self.draw(); });
  };

  Viewer.prototype.pick = function (e) {
    var r = this.canvas.getBoundingClientRect(), x = e.clientX - r.left, y = e.clientY - r.top, best = null, bd = 15 * 15;
    (this.picks || []).forEach(function (p) {
      var d = (p[0] - x) * (p[0] - x) + (p[1] - y) * (p[1] - y);
      if (d < bd) { bd = d; best = p; }
    });
    this.info.textContent = best ? best[2] : "nothing within 15 px of the click";
  };

  Viewer.prototype.draw = function () {
    if (!this.ready) return;
    var c = this.canvas, ctx = this.ctx, dpr = window.devicePixelRatio || 1;
    var W = c.clientWidth || 800, H = c.clientHeight || 480;
    if (c.width !== Math.round(W * dpr) || c.height !== Math.round(H * dpr)) { c.width = Math.round(W * dpr); c.height = Math.round(H * dpr); }
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = "#fff"; ctx.fillRect(0, 0, W, H);
    var P = this.positions(), n = P.length / 3;
    var cy = Math.cos(this.yaw), sy = Math.sin(this.yaw), cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    var s = this.zoom * 0.95 * Math.min(W - 200, H) / this.size, ox = (W - 200) / 2 + this.pan[0], oy = H / 2 + this.pan[1];
    var sx = new Float32Array(n), syy = new Float32Array(n), dep = new Float32Array(n);
    for (var i = 0; i < n; i++) {
      var x = P[3 * i] - this.center[0], y = P[3 * i + 1] - this.center[1], z = P[3 * i + 2] - this.center[2];
      var x1 = cy * x - sy * y, y1 = sy * x + cy * y;
      sx[i] = ox + s * x1; syy[i] = oy - s * (z * cp + y1 * sp); dep[i] = y1 * cp - z * sp;
    }
    var items = [], T = this.tris, L = this.lines, tc = this.triColour(), lc = this.lineColour();
    for (var j = 0; j < T.length / 3; j++) {
      var a = T[3 * j], b = T[3 * j + 1], d = T[3 * j + 2];
      items.push([(dep[a] + dep[b] + dep[d]) / 3, 0, j]);
    }
    // lines in PIECES parts, each sorted by its own depth (a long bar passes behind the membrane)
    var PIECES = 8;
    for (j = 0; j < L.length / 2; j++)
      for (var q = 0; q < PIECES; q++) {
        var f0 = (q + 0.5) / PIECES;
        items.push([dep[L[2 * j]] * (1 - f0) + dep[L[2 * j + 1]] * f0 - 1e-3 * this.size, 1, j, q / PIECES, (q + 1) / PIECES]);
      }
    items.sort(function (p, q) { return q[0] - p[0]; });
    var picks = [];
    ctx.lineJoin = "round"; ctx.lineCap = "round";
    for (var k = 0; k < items.length; k++) {
      var it = items[k], m = it[2];
      if (it[1] === 0) {
        a = T[3 * m]; b = T[3 * m + 1]; d = T[3 * m + 2];
        var ux = P[3 * b] - P[3 * a], uy = P[3 * b + 1] - P[3 * a + 1], uz = P[3 * b + 2] - P[3 * a + 2];
        var vx = P[3 * d] - P[3 * a], vy = P[3 * d + 1] - P[3 * a + 1], vz = P[3 * d + 2] - P[3 * a + 2];
        var nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx, nn = Math.hypot(nx, ny, nz) || 1;
        var ndep = ((sy * nx + cy * ny) * cp - nz * sp) / nn;
        var col = tc ? colour(tc.stops, (tc.values[m] - tc.lo) / (tc.hi - tc.lo)) : [222, 196, 120];
        var fill = rgb(col, 0.55 + 0.45 * Math.abs(ndep));
        ctx.fillStyle = fill; ctx.strokeStyle = fill; ctx.lineWidth = 0.6;
        ctx.beginPath(); ctx.moveTo(sx[a], syy[a]); ctx.lineTo(sx[b], syy[b]); ctx.lineTo(sx[d], syy[d]); ctx.closePath();
        ctx.fill(); ctx.stroke();
        if (tc) picks.push([(sx[a] + sx[b] + sx[d]) / 3, (syy[a] + syy[b] + syy[d]) / 3, "membrane: " + tc.title + " = " + fmt(tc.values[m])]);
      } else {
        a = L[2 * m]; b = L[2 * m + 1];
        var bar = this.lineKind[m] === 0;
        var known = lc && isFinite(lc.values[m]);
        col = known ? colour(lc.stops, (lc.values[m] - lc.lo) / (lc.hi - lc.lo)) : (bar ? [139, 69, 19] : [31, 119, 180]);
        ctx.strokeStyle = rgb(col, bar && known ? 0.8 : 1); ctx.lineWidth = bar ? 5 : 1.8;
        var t0 = it[3], t1 = it[4];
        ctx.beginPath(); ctx.moveTo(sx[a] + t0 * (sx[b] - sx[a]), syy[a] + t0 * (syy[b] - syy[a]));
        ctx.lineTo(sx[a] + t1 * (sx[b] - sx[a]), syy[a] + t1 * (syy[b] - syy[a])); ctx.stroke();
        if (t0 === 0) picks.push([(sx[a] + sx[b]) / 2, (syy[a] + syy[b]) / 2, (bar ? "bar" : "tendon element") + " " + m +
                    (known ? ": " + lc.title + " = " + fmt(lc.values[m]) : "")]);
      }
    }
    this.picks = picks;
    var x0 = W - 190;
    if (tc) this.colourBar(x0, 30, tc);
    if (lc) this.colourBar(x0 + 95, 30, lc);
    if (!lc) this.legend(x0 + 95, 30);
    else if (hasUnknown(lc.values)) this.legend(x0 + 95, 300, [["bar: no force", "#8b4513", 5]]);
    this.axes(60, H - 60, cy, sy, cp, sp);
    c.dataset.primitives = T.length / 3 + L.length / 2;
  };
  Viewer.prototype.colourBar = function (x, y, cm) {
    var ctx = this.ctx, h = 200;
    ctx.fillStyle = "#222"; ctx.font = "11px sans-serif";
    var words = cm.title.split(" "), line = "", ly = y;
    for (var k = 0; k < words.length; k++) {
      if ((line + " " + words[k]).length > 15 && line) { ctx.fillText(line, x - 4, ly); ly += 12; line = words[k]; }
      else line = line ? line + " " + words[k] : words[k];
    }
    ctx.fillText(line, x - 4, ly);
    var y0 = ly + 12;
    for (var i = 0; i < h; i++) { ctx.fillStyle = rgb(colour(cm.stops, 1 - i / h)); ctx.fillRect(x, y0 + i, 16, 1.5); }
    ctx.fillStyle = "#222";
    for (k = 0; k <= 4; k++) ctx.fillText((k === 0 && cm.clipped ? ">= " : "") + fmt(cm.hi - k * (cm.hi - cm.lo) / 4), x + 20, y0 + 4 + k * h / 4);
    if (cm.clipped) ctx.fillText("(98th percentile)", x - 4, y0 + h + 16);
  };
  function hasUnknown(a) { for (var i = 0; i < a.length; i++) if (!isFinite(a[i])) return true; return false; }
  Viewer.prototype.legend = function (x, y, rows) {
    var ctx = this.ctx;
    ctx.font = "11px sans-serif";
    (rows || [["bar", "#8b4513", 5], ["tendon", "#1f77b4", 2]]).forEach(function (r, i) {
      ctx.strokeStyle = r[1]; ctx.lineWidth = r[2];
      ctx.beginPath(); ctx.moveTo(x, y + 20 * i); ctx.lineTo(x + 20, y + 20 * i); ctx.stroke();
      ctx.fillStyle = "#222"; ctx.fillText(r[0], x + 26, y + 4 + 20 * i);
    });
  };
  Viewer.prototype.axes = function (x, y, cy, sy, cp, sp) {
    var ctx = this.ctx, e = [[1, 0, 0], [0, 1, 0], [0, 0, 1]], names = ["x", "y", "z"], cols = ["#c00", "#080", "#00c"];
    ctx.font = "12px sans-serif"; ctx.lineWidth = 2;
    for (var i = 0; i < 3; i++) {
      var x1 = cy * e[i][0] - sy * e[i][1], y1 = sy * e[i][0] + cy * e[i][1];
      var px = x + 30 * x1, py = y - 30 * (e[i][2] * cp + y1 * sp);
      ctx.strokeStyle = cols[i]; ctx.beginPath(); ctx.moveTo(x, y); ctx.lineTo(px, py); ctx.stroke();
      ctx.fillStyle = cols[i]; ctx.fillText(names[i], px + 3, py + 3);
    }
  };

  window.tmfemViewers = [];
  document.querySelectorAll(".viewer").forEach(function (root) {
    var scene = JSON.parse(document.getElementById(root.id + "-data").textContent);
    window.tmfemViewers.push(new Viewer(root, scene));
  });
})();
