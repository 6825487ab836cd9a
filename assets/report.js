// flexcraft report: interactive line charts (hover to read, drag to zoom a time window,
// double-click to reset) and the deployment animation. No dependencies, no network.
"use strict";
(function () {
  var status = "ok";
  window.addEventListener("error", function (e) {
    status = "error: " + e.message;
    document.body.setAttribute("data-status", status);
  });
  var NS = "http://www.w3.org/2000/svg";
  var COLORS = ["#1f5ac8", "#dc3c28", "#1e9646", "#963cb4", "#e68c14", "#14a0aa", "#787878", "#b42878"];
  function el(tag, attrs, parent) {
    var e = document.createElementNS(NS, tag);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  }
  function text(parent, x, y, s, anchor, cls) {
    var t = el("text", { x: x, y: y, "text-anchor": anchor || "start", "class": cls || "" }, parent);
    t.textContent = s;
    return t;
  }
  function ticks(lo, hi, n) {
    var span = hi - lo;
    if (!(span > 0)) return [lo];
    var step = Math.pow(10, Math.floor(Math.log10(span / n)));
    var err = span / n / step;
    if (err >= 7.5) step *= 10; else if (err >= 3.5) step *= 5; else if (err >= 1.5) step *= 2;
    var out = [];
    for (var v = Math.ceil(lo / step) * step; v <= hi + 1e-9 * step; v += step) out.push(v);
    return out;
  }
  // Tick labels: an SI prefix on the axis unit (or a shared power of ten) keeps the labels'
  // magnitudes in [1, 1000); each label has the decimals its tick step needs and a value
  // within rounding of zero reads "0" (flexcraft's PNG/SVG figures use the same rules).
  var PREFIX = { "-12": "p", "-9": "n", "-6": "µ", "-3": "m", "3": "k", "6": "M", "9": "G" };
  var PREFIXABLE = ["m", "rad", "N", "N·m", "J", "N·s", "m/s", "rad/s"];
  function axisScale(a, label) {
    if (!(a > 0) || (a >= 1e-2 && a < 1e4)) return [1, label];
    var e = Math.floor(Math.log10(a) / 3) * 3, f = Math.pow(10, e);
    var i = label.lastIndexOf("[");
    if (i < 0) return [f, label + " [×1e" + e + "]"];
    var unit = label.slice(i + 1).replace(/\]$/, "");
    if (PREFIX[e] && PREFIXABLE.indexOf(unit) >= 0) return [f, label.slice(0, i) + "[" + PREFIX[e] + unit + "]"];
    return [f, label.slice(0, i) + "[×1e" + e + " " + unit + "]"];
  }
  function tickLabel(v, step) {
    if (Math.abs(v) < Math.abs(step) * 1e-6) return "0";
    var d = Math.max(0, Math.min(9, Math.ceil(-Math.log10(Math.abs(step)) - 1e-9)));
    var s = v.toFixed(d);
    return /^-?0(\.0*)?$/.test(s) ? "0" : s;
  }
  function fmt(v) {
    if (v === 0) return "0";
    var a = Math.abs(v);
    if (a >= 1e4 || a < 1e-3) return v.toExponential(2);
    return parseFloat(v.toPrecision(4)).toString();
  }
  function lower(xs, x) {
    var lo = 0, hi = xs.length - 1;
    while (lo < hi) { var m = (lo + hi) >> 1; if (xs[m] < x) lo = m + 1; else hi = m; }
    return lo;
  }
  function Chart(fig, spec) {
    var W = 960, H = 320, L = 70, R = 210, T = 28, B = 44;
    var full = [Infinity, -Infinity];
    spec.series.forEach(function (s) {
      for (var i = 0; i < s.x.length; i++) { full[0] = Math.min(full[0], s.x[i]); full[1] = Math.max(full[1], s.x[i]); }
    });
    var view = full.slice();
    var svg = el("svg", { viewBox: "0 0 " + W + " " + H, "class": "chart", role: "img" }, fig);
    var tip = document.createElement("div");
    tip.className = "tip";
    fig.appendChild(tip);
    function draw() {
      while (svg.firstChild) svg.removeChild(svg.firstChild);
      var ylo = Infinity, yhi = -Infinity;
      spec.series.forEach(function (s) {
        for (var i = 0; i < s.x.length; i++) {
          if (s.x[i] >= view[0] && s.x[i] <= view[1] && isFinite(s.y[i])) {
            ylo = Math.min(ylo, s.y[i]); yhi = Math.max(yhi, s.y[i]);
          }
        }
      });
      if (!isFinite(ylo)) { ylo = 0; yhi = 1; }
      if (yhi - ylo <= 1e-12 * (Math.abs(ylo) + Math.abs(yhi)) || yhi === ylo) {
        var c = 0.5 * (ylo + yhi), d = Math.max(Math.abs(c) * 0.1, 1e-12); ylo = c - d; yhi = c + d;
      }
      var pad = 0.05 * (yhi - ylo); ylo -= pad; yhi += pad;
      fig.setAttribute("data-view", view[0] + "," + view[1]);
      var sx = function (x) { return L + (x - view[0]) / (view[1] - view[0] || 1) * (W - L - R); };
      var sy = function (y) { return H - B - (y - ylo) / (yhi - ylo) * (H - T - B); };
      chart.sx = sx; chart.sy = sy;
      // A long title is drawn smaller, never beyond the chart (nor below 9 px).
      var title = text(svg, W / 2, 18, spec.title, "middle", "title");
      var tw = title.getComputedTextLength ? title.getComputedTextLength() : 0;
      if (tw > W - 20) title.style.fontSize = Math.max(9, 14 * (W - 20) / tw).toFixed(1) + "px";
      var xt = ticks(view[0], view[1], 8), xstep = xt.length > 1 ? xt[1] - xt[0] : 1;
      xt.forEach(function (v) {
        el("line", { x1: sx(v), x2: sx(v), y1: T, y2: H - B, "class": "grid" }, svg);
        text(svg, sx(v), H - B + 16, tickLabel(v, xstep), "middle", "tick");
      });
      var ys = axisScale(Math.max(Math.abs(ylo + pad), Math.abs(yhi - pad)), spec.ylabel), f = ys[0];
      var yt = ticks(ylo / f, yhi / f, 6), ystep = yt.length > 1 ? yt[1] - yt[0] : 1;
      yt.forEach(function (v) {
        el("line", { x1: L, x2: W - R, y1: sy(v * f), y2: sy(v * f), "class": "grid" }, svg);
        text(svg, L - 6, sy(v * f) + 4, tickLabel(v, ystep), "end", "tick");
      });
      (spec.markers || []).forEach(function (m) {
        if (m >= view[0] && m <= view[1]) el("line", { x1: sx(m), x2: sx(m), y1: T, y2: H - B, "class": "marker" }, svg);
      });
      el("rect", { x: L, y: T, width: W - L - R, height: H - T - B, "class": "frame" }, svg);
      text(svg, (L + W - R) / 2, H - 8, spec.xlabel, "middle", "label");
      var yl = text(svg, 14, (T + H - B) / 2, ys[1], "middle", "label");
      yl.setAttribute("transform", "rotate(-90 14 " + (T + H - B) / 2 + ")");
      spec.series.forEach(function (s, k) {
        var i0 = Math.max(0, lower(s.x, view[0]) - 1), i1 = Math.min(s.x.length - 1, lower(s.x, view[1]) + 1);
        var stride = Math.max(1, Math.floor((i1 - i0) / 3000));
        var pts = [];
        for (var i = i0; i <= i1; i += stride) pts.push(sx(s.x[i]).toFixed(1) + "," + sy(s.y[i]).toFixed(1));
        el("polyline", { points: pts.join(" "), stroke: COLORS[k % COLORS.length], "class": "series" }, svg);
      });
      var ly = T + 14;
      spec.series.slice(0, 10).forEach(function (s, k) {
        el("line", { x1: W - R + 10, x2: W - R + 28, y1: ly - 4, y2: ly - 4, stroke: COLORS[k % COLORS.length], "stroke-width": 2 }, svg);
        text(svg, W - R + 32, ly, s.name, "start", "legend");
        ly += 15;
      });
      chart.cursor = el("line", { y1: T, y2: H - B, "class": "cursor", visibility: "hidden" }, svg);
      chart.sel = el("rect", { y: T, height: H - T - B, "class": "selection", visibility: "hidden" }, svg);
    }
    var chart = { draw: draw };
    function dataX(ev) {
      var r = svg.getBoundingClientRect();
      var px = (ev.clientX - r.left) / r.width * W;
      return view[0] + (px - L) / (W - L - R) * (view[1] - view[0]);
    }
    var drag = null;
    svg.addEventListener("mousemove", function (ev) {
      var x = Math.min(view[1], Math.max(view[0], dataX(ev)));
      chart.cursor.setAttribute("x1", chart.sx(x)); chart.cursor.setAttribute("x2", chart.sx(x));
      chart.cursor.setAttribute("visibility", "visible");
      var lines = spec.series.map(function (s) {
        var i = Math.min(s.x.length - 1, lower(s.x, x));
        return s.name + ": " + fmt(s.y[i]);
      });
      var s0 = spec.series[0];
      tip.textContent = spec.xlabel + " " + fmt(s0.x[Math.min(s0.x.length - 1, lower(s0.x, x))]) + " — " + lines.join(", ");
      if (drag !== null) {
        var a = chart.sx(Math.min(drag, x)), b = chart.sx(Math.max(drag, x));
        chart.sel.setAttribute("x", a); chart.sel.setAttribute("width", b - a);
        chart.sel.setAttribute("visibility", "visible");
      }
    });
    svg.addEventListener("mouseleave", function () { chart.cursor.setAttribute("visibility", "hidden"); });
    svg.addEventListener("mousedown", function (ev) { drag = dataX(ev); ev.preventDefault(); });
    svg.addEventListener("mouseup", function (ev) {
      if (drag === null) return;
      var x = dataX(ev), a = Math.min(drag, x), b = Math.max(drag, x);
      drag = null;
      if (b - a > 1e-9 * (full[1] - full[0])) { view = [a, b]; }
      draw();
    });
    svg.addEventListener("dblclick", function () { view = full.slice(); draw(); });
    draw();
  }
  function Animation(root, spec) {
    var frames = spec.frames;
    var box = spec.box;
    var W = 760, H = 420, m = 20;
    var s = Math.min((W - 2 * m) / (box[1] - box[0]), (H - 2 * m) / (box[3] - box[2]));
    var X = function (u) { return m + (u - box[0]) * s; };
    var Y = function (v) { return H - m - (v - box[2]) * s; };
    var svg = el("svg", { viewBox: "0 0 " + W + " " + H, "class": "anim", role: "img" }, root.querySelector(".stage"));
    el("rect", { x: 0, y: 0, width: W, height: H, fill: "#fbfbfd" }, svg);
    var hub = el("circle", { r: 6, "class": "hub" }, svg);
    var line = el("polyline", { "class": "panels" }, svg);
    var joints = el("g", {}, svg);
    var label = root.querySelector(".time");
    var slider = root.querySelector("input[type=range]");
    var button = root.querySelector("button");
    slider.max = frames.length - 1;
    function show(k) {
      var f = frames[k];
      line.setAttribute("points", f.p.map(function (p) { return X(p[0]).toFixed(1) + "," + Y(p[1]).toFixed(1); }).join(" "));
      hub.setAttribute("cx", X(f.h[0])); hub.setAttribute("cy", Y(f.h[1]));
      while (joints.firstChild) joints.removeChild(joints.firstChild);
      f.p.forEach(function (p) { el("circle", { cx: X(p[0]), cy: Y(p[1]), r: 3, "class": "joint" }, joints); });
      label.textContent = "t = " + f.t.toFixed(2) + " s";
      slider.value = k;
      root.setAttribute("data-frame", k);
    }
    var timer = null;
    button.addEventListener("click", function () {
      if (timer) { clearInterval(timer); timer = null; button.textContent = "play"; return; }
      button.textContent = "pause";
      timer = setInterval(function () {
        var k = +slider.value + 1;
        if (k >= frames.length) { clearInterval(timer); timer = null; button.textContent = "play"; return; }
        show(k);
      }, 40);
    });
    slider.addEventListener("input", function () { show(+slider.value); });
    var m0 = /frame=(\w+)/.exec(location.hash);
    var start = 0;
    if (m0) { start = m0[1] === "last" ? frames.length - 1 : Math.min(frames.length - 1, +m0[1] || 0); }
    show(start);
  }
  // The 3-D view: a canvas with its own orthographic projection (drag to rotate, wheel to
  // zoom), painter's order; the spacecraft as described, the deployment (hub motion, panels
  // unfolding, beams' tip deflection exaggerated) and the first elastic modes (exaggerated).
  function View3D(root, spec) {
    var canvas = root.querySelector("canvas"), ctx = canvas.getContext("2d");
    var W = canvas.width, H = canvas.height;
    var select = root.querySelector("select"), button = root.querySelector("button");
    var slider = root.querySelector("input[type=range]"), label = root.querySelector(".time");
    var yaw = -0.85, pitch = 0.45, zoom = 1, frame = 0, phase = Math.PI / 2, timer = null;
    var ext = spec.extent, dep = spec.deploy;
    var what = dep ? "deploy" : (spec.modes.length ? "mode:0" : "structure");
    function add(a, b) { return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]; }
    function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
    function mul(a, k) { return [a[0] * k, a[1] * k, a[2] * k]; }
    function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
    function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
    function unit(a) { var n = Math.sqrt(dot(a, a)) || 1; return mul(a, 1 / n); }
    // Rodrigues: R(ρ) p = p cos θ + (k × p) sin θ + k (k·p)(1 − cos θ), θ = |ρ|, k = ρ/θ.
    function rotate(rho, p) {
      var t = Math.sqrt(dot(rho, rho));
      if (t < 1e-15) return p;
      var k = mul(rho, 1 / t), c = Math.cos(t), s = Math.sin(t);
      return add(add(mul(p, c), mul(cross(k, p), s)), mul(k, dot(k, p) * (1 - c)));
    }
    // The view's centre and size: the bounding box of the hub, beams and plates.
    var box = (function () {
      var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
      var take = function (p) { for (var i = 0; i < 3; i++) { lo[i] = Math.min(lo[i], p[i]); hi[i] = Math.max(hi[i], p[i]); } };
      spec.beams.concat(spec.plates).forEach(function (c) { c.pts.forEach(take); });
      var h = spec.hub, a = h.kind === "cylinder" ? mul(unit(h.axis), h.length / 2) : h.half;
      take(add(h.center, a)); take(sub(h.center, a));
      return [lo, hi];
    })();
    var center = mul(add(box[0], box[1]), 0.5);
    ext = 0.5 * Math.sqrt(dot(sub(box[1], box[0]), sub(box[1], box[0]))) || ext;
    function pxScale() { return zoom * 0.9 * Math.min(W, H) / (2 * ext); }
    // View coordinates: yaw about z, then pitch about the screen's x; depth grows away.
    function toView(d) {
      var cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
      var x1 = cy * d[0] - sy * d[1], y1 = sy * d[0] + cy * d[1];
      return [x1, cp * y1 - sp * d[2], sp * y1 + cp * d[2]];
    }
    function project(p) {
      var v = toView(sub(p, center)), s = pxScale();
      return [W / 2 + s * v[0], H / 2 - s * v[2], v[1]];
    }
    function shade(rgb, normal) {
      var n = toView(unit(normal));
      var b = 0.45 + 0.55 * Math.abs(n[1]);
      return "rgb(" + rgb.map(function (c) { return Math.round(c * b); }).join(",") + ")";
    }
    // Scene for the current state: a list of {z, draw()} drawn far to near.
    function scene() {
      var items = [];
      var hx = [0, 0, 0], hr = [0, 0, 0], f = null, m = null;
      if (what === "deploy" && dep) { f = dep.frames[frame]; hx = f.hx; hr = f.hr; }
      if (what.indexOf("mode:") === 0) m = spec.modes[+what.slice(5)];
      var wave = Math.sin(phase);
      var c0 = dep ? dep.c : spec.hub.center;
      function world(p) { return add(add(c0, hx), rotate(hr, sub(p, c0))); }
      function poly(pts, fill, stroke, normal) {
        var q = pts.map(function (p) { return project(world(p)); });
        var z = q.reduce(function (a, p) { return a + p[2]; }, 0) / q.length;
        items.push({ z: z, draw: function () {
          ctx.beginPath(); ctx.moveTo(q[0][0], q[0][1]);
          for (var i = 1; i < q.length; i++) ctx.lineTo(q[i][0], q[i][1]);
          ctx.closePath();
          ctx.fillStyle = normal ? shade(fill, rotate(hr, normal)) : "rgb(" + fill.join(",") + ")";
          ctx.fill();
          if (stroke) { ctx.strokeStyle = stroke; ctx.lineWidth = 0.6; ctx.stroke(); }
        } });
      }
      // Hub.
      var hub = spec.hub;
      if (hub.kind === "cylinder") {
        var a = unit(hub.axis), u = unit(cross(a, Math.abs(a[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0])), v = cross(a, u);
        var ring = function (s) {
          var out = [];
          for (var i = 0; i < 32; i++) {
            var t = 2 * Math.PI * i / 32;
            out.push(add(add(hub.center, mul(a, s * hub.length / 2)), add(mul(u, hub.radius * Math.cos(t)), mul(v, hub.radius * Math.sin(t)))));
          }
          return out;
        };
        var top = ring(1), bot = ring(-1);
        for (var i = 0; i < 32; i++) {
          var j = (i + 1) % 32, mid = mul(add(sub(top[i], hub.center), sub(top[j], hub.center)), 0.5);
          poly([top[i], top[j], bot[j], bot[i]], [150, 160, 175], null, sub(mid, mul(a, dot(mid, a))));
        }
        poly(top, [170, 178, 190], "#556", a); poly(bot, [170, 178, 190], "#556", mul(a, -1));
      } else {
        var h = hub.half, cc = hub.center;
        var corner = function (sx, sy, sz) { return add(cc, [sx * h[0], sy * h[1], sz * h[2]]); };
        [[0, 1], [0, -1], [1, 1], [1, -1], [2, 1], [2, -1]].forEach(function (fc) {
          var ax = fc[0], s = fc[1], pts = [], nrm = [0, 0, 0];
          nrm[ax] = s;
          [[-1, -1], [1, -1], [1, 1], [-1, 1]].forEach(function (uv) {
            var sgn = [0, 0, 0]; sgn[ax] = s; sgn[(ax + 1) % 3] = uv[0]; sgn[(ax + 2) % 3] = uv[1];
            pts.push(corner(sgn[0], sgn[1], sgn[2]));
          });
          poly(pts, [150, 160, 175], "#556", nrm);
        });
      }
      // Beams: tubes of their diameter (a thick line per segment).
      spec.beams.forEach(function (b, bi) {
        var tipIndex = f ? dep.tip_beams.indexOf(bi) : -1;
        var pts = b.pts.map(function (p, k) {
          var xi = k / (b.pts.length - 1);
          if (m) return add(p, mul(m.beams[bi][k], wave));
          if (f && tipIndex >= 0) return add(p, mul(f.tips[tipIndex], xi * xi * (3 - xi) / 2));
          return p;
        });
        for (var k = 0; k + 1 < pts.length; k++) {
          (function (p0, p1) {
            var q0 = project(world(p0)), q1 = project(world(p1));
            items.push({ z: 0.5 * (q0[2] + q1[2]), draw: function () {
              ctx.strokeStyle = "#5a6678"; ctx.lineCap = "round";
              ctx.lineWidth = Math.max(2, b.d * pxScale());
              ctx.beginPath(); ctx.moveTo(q0[0], q0[1]); ctx.lineTo(q1[0], q1[1]); ctx.stroke();
            } });
          })(pts[k], pts[k + 1]);
        }
      });
      // Plates (the deploying one as its panels during the deployment).
      spec.plates.forEach(function (pl, pi) {
        if (f && dep.plate === pi) return;
        var at = function (i, j) {
          var k = i * pl.ny + j, p = pl.pts[k];
          return m ? add(p, mul(m.plates[pi][k], wave)) : p;
        };
        for (var i = 0; i + 1 < pl.nx; i++) {
          for (var j = 0; j + 1 < pl.ny; j++) {
            var p00 = at(i, j), p10 = at(i + 1, j), p11 = at(i + 1, j + 1), p01 = at(i, j + 1);
            poly([p00, p10, p11, p01], [60, 90, 170], "rgba(20,30,60,0.25)", cross(sub(p10, p00), sub(p01, p00)));
          }
        }
      });
      if (f) {
        var half = mul(dep.eb, dep.width / 2);
        // The panels ride on the carrying beam's (exaggerated) tip deflection.
        var shift = dep.carrier === null ? [0, 0, 0] : f.tips[dep.carrier];
        var body = function (uv) { return add(add(add(dep.origin, shift), mul(dep.ea, uv[0])), mul(dep.n, uv[1])); };
        for (var k = 0; k + 1 < f.p.length; k++) {
          var a0 = body(f.p[k]), a1 = body(f.p[k + 1]);
          poly([sub(a0, half), sub(a1, half), add(a1, half), add(a0, half)], [60, 90, 170], "#223", cross(sub(a1, a0), dep.eb));
        }
      }
      spec.masses.forEach(function (ms) {
        var q = project(world(ms.p));
        items.push({ z: q[2], draw: function () {
          ctx.fillStyle = "#b8860b"; ctx.beginPath();
          ctx.arc(q[0], q[1], Math.max(3, ms.r * pxScale()), 0, 2 * Math.PI); ctx.fill();
        } });
      });
      return items;
    }
    function triad() {
      var o = [56, H - 56], names = ["x", "y", "z"], colors = ["#d22", "#1a1", "#22d"];
      for (var i = 0; i < 3; i++) {
        var e = [0, 0, 0]; e[i] = 1;
        var v = toView(e), p = [o[0] + 40 * v[0], o[1] - 40 * v[2]];
        ctx.strokeStyle = colors[i]; ctx.lineWidth = 2.5;
        ctx.beginPath(); ctx.moveTo(o[0], o[1]); ctx.lineTo(p[0], p[1]); ctx.stroke();
        ctx.fillStyle = colors[i]; ctx.font = "13px sans-serif"; ctx.fillText(names[i], p[0] + 3, p[1] - 3);
      }
    }
    function scaleBar() {
      var want = 0.25 * ext / zoom, k = Math.pow(10, Math.floor(Math.log10(want)));
      var len = [1, 2, 5, 10].map(function (m) { return m * k; }).filter(function (l) { return l <= want; }).pop() || k;
      var px = len * pxScale(), x0 = W - 30 - px, y0 = H - 30;
      ctx.strokeStyle = "#222"; ctx.lineWidth = 2;
      ctx.beginPath(); ctx.moveTo(x0, y0 - 5); ctx.lineTo(x0, y0); ctx.lineTo(x0 + px, y0); ctx.lineTo(x0 + px, y0 - 5); ctx.stroke();
      ctx.fillStyle = "#222"; ctx.font = "13px sans-serif"; ctx.textAlign = "center";
      ctx.fillText(len + " m", x0 + px / 2, y0 - 8); ctx.textAlign = "start";
    }
    function render() {
      ctx.fillStyle = "#fbfbfd"; ctx.fillRect(0, 0, W, H);
      var items = scene();
      items.sort(function (a, b) { return b.z - a.z; });
      items.forEach(function (it) { it.draw(); });
      triad(); scaleBar();
      var text;
      if (what === "deploy" && dep) {
        text = "deployment, t = " + dep.frames[frame].t.toFixed(2) + " s; beam tip deflection ×" + dep.k_tip.toPrecision(3) + " (cantilever shape)";
      } else if (what.indexOf("mode:") === 0) {
        var md = spec.modes[+what.slice(5)];
        text = "mode " + md.n + ", " + md.f.toFixed(4) + " Hz; deflection ×" + md.k.toPrecision(3) + " (√kg·m of modal amplitude; largest 10 % of the size)";
      } else text = "undeformed";
      label.textContent = text;
      root.setAttribute("data-state", what + ":" + frame + ":" + phase.toFixed(3) + ":" + yaw.toFixed(3));
    }
    if (dep) { var o = document.createElement("option"); o.value = "deploy"; o.textContent = "deployment"; select.appendChild(o); }
    spec.modes.forEach(function (md, k) {
      var o = document.createElement("option"); o.value = "mode:" + k;
      o.textContent = "mode " + md.n + " (" + md.f.toFixed(4) + " Hz)"; select.appendChild(o);
    });
    select.value = what;
    function setSlider() {
      if (what === "deploy" && dep) { slider.max = dep.frames.length - 1; slider.value = frame; }
      else { slider.max = 100; slider.value = Math.round(100 * (phase % (2 * Math.PI)) / (2 * Math.PI)); }
    }
    select.addEventListener("change", function () { what = select.value; frame = 0; phase = Math.PI / 2; setSlider(); render(); });
    slider.addEventListener("input", function () {
      if (what === "deploy") frame = +slider.value; else phase = 2 * Math.PI * slider.value / 100;
      render();
    });
    button.addEventListener("click", function () {
      if (timer) { clearInterval(timer); timer = null; button.textContent = "play"; return; }
      button.textContent = "pause";
      timer = setInterval(function () {
        if (what === "deploy" && dep) {
          if (frame + 1 >= dep.frames.length) { clearInterval(timer); timer = null; button.textContent = "play"; return; }
          frame++;
        } else phase += 0.15;
        setSlider(); render();
      }, 40);
    });
    var drag = null;
    canvas.addEventListener("mousedown", function (ev) { drag = [ev.clientX, ev.clientY]; ev.preventDefault(); });
    window.addEventListener("mouseup", function () { drag = null; });
    canvas.addEventListener("mousemove", function (ev) {
      if (!drag) return;
      yaw += 0.01 * (ev.clientX - drag[0]);
      pitch = Math.max(-1.5, Math.min(1.5, pitch + 0.01 * (ev.clientY - drag[1])));
      drag = [ev.clientX, ev.clientY]; render();
    });
    canvas.addEventListener("wheel", function (ev) { zoom *= Math.exp(-0.001 * ev.deltaY); ev.preventDefault(); render(); }, { passive: false });
    var hv = /view=(\w+)/.exec(location.hash);
    if (hv && dep && what === "deploy") frame = hv[1] === "last" ? dep.frames.length - 1 : 0;
    setSlider(); render();
    return {
      render: render,
      set: function (w, k) { what = w; select.value = w; if (w === "deploy") frame = k; else phase = k; setSlider(); render(); },
      frames: dep ? dep.frames.length : 0,
      rotate: function (dy) { yaw += dy; render(); },
      pixels: function () { return ctx.getImageData(0, 0, W, H).data; },
    };
  }
  function data(node) {
    return JSON.parse(node.querySelector("script[type='application/json']").textContent);
  }
  document.querySelectorAll("figure.plot").forEach(function (f) { Chart(f, data(f)); });
  document.querySelectorAll(".animation").forEach(function (a) { Animation(a, data(a)); });
  var views = [];
  document.querySelectorAll(".view3d").forEach(function (v) { views.push(View3D(v, data(v))); });
  // #only=ID: that section alone (for screenshots).
  var only = /only=([\w-]+)/.exec(location.hash);
  if (only) {
    document.querySelectorAll("section, header, footer").forEach(function (s) {
      if (s.id !== only[1]) s.style.display = "none";
    });
  }
  if (status === "ok") document.body.setAttribute("data-status", "ok");
  // #selftest: hover and drag-zoom the first chart with synthetic mouse events (the browser
  // test reads the verdict from body[data-selftest]).
  if (/selftest/.test(location.hash)) {
    var verdict = "ok";
    try {
      var fig = document.querySelector("figure.plot");
      var svg = fig.querySelector("svg");
      var r = svg.getBoundingClientRect();
      var at = function (type, fx) {
        svg.dispatchEvent(new MouseEvent(type, { clientX: r.left + fx * r.width, clientY: r.top + 0.5 * r.height, bubbles: true }));
      };
      var span = function () { var v = fig.getAttribute("data-view").split(",").map(Number); return v[1] - v[0]; };
      var full = span();
      at("mousemove", 0.5);
      if (!fig.querySelector(".tip").textContent) verdict = "no hover readout";
      at("mousedown", 0.3); at("mousemove", 0.6); at("mouseup", 0.6);
      if (!(span() < 0.5 * full)) verdict = "drag did not zoom";
      svg.dispatchEvent(new MouseEvent("dblclick", { bubbles: true }));
      if (span() !== full) verdict = "double-click did not reset";
      // No axis repeats a tick label; no tick shows rounding noise.
      document.querySelectorAll("figure.plot svg").forEach(function (svg, k) {
        var axes = {};
        svg.querySelectorAll("text.tick").forEach(function (t) {
          var key = t.getAttribute("text-anchor") === "end" ? "y" + t.getAttribute("x") : "x" + t.getAttribute("y");
          (axes[key] = axes[key] || []).push(t.textContent);
          if (/e-(1\d|[2-9]\d)/.test(t.textContent)) verdict = "chart " + k + ": noise tick " + t.textContent;
        });
        Object.keys(axes).forEach(function (a) {
          var seen = {};
          axes[a].forEach(function (l) { if (seen[l]) verdict = "chart " + k + ": tick " + l + " repeated"; seen[l] = 1; });
        });
      });
      // Tables: per column, no non-zero number below 1e-9 of the column's largest.
      document.querySelectorAll("table").forEach(function (tb) {
        var cols = [];
        Array.prototype.forEach.call(tb.rows, function (tr) {
          Array.prototype.forEach.call(tr.cells, function (td, c) {
            if (td.tagName !== "TD" || td.querySelector("table") || !/^\s*-?[0-9.]+(e-?[0-9]+)?\s*$/.test(td.textContent)) return;
            (cols[c] = cols[c] || []).push(parseFloat(td.textContent));
          });
        });
        cols.forEach(function (vals, c) {
          var big = vals.reduce(function (a, v) { return Math.max(a, Math.abs(v)); }, 0);
          vals.forEach(function (v) {
            if (v !== 0 && Math.abs(v) < 1e-9 * big) verdict = "table " + (tb.id || "?") + " column " + c + ": " + v + " is rounding noise";
          });
        });
      });
    } catch (e) { verdict = "error: " + e.message; }
    document.body.setAttribute("data-selftest", verdict);
    // The 3-D view: frames 0 and last drawn and different, rotation changes the picture, a
    // mode is drawn and moves.
    var v3 = "ok";
    try {
      var V = views[0];
      var ink = function (px) {
        var n = 0;
        for (var i = 0; i < px.length; i += 4) if (px[i] < 235 || px[i + 1] < 235 || px[i + 2] < 235) n++;
        return n / (px.length / 4);
      };
      var differ = function (a, b) { for (var i = 0; i < a.length; i++) if (a[i] !== b[i]) return true; return false; };
      if (!V) v3 = "no 3-D view";
      else {
        if (V.frames > 0) {
          V.set("deploy", 0); var f0 = V.pixels();
          V.set("deploy", V.frames - 1); var f1 = V.pixels();
          if (!(ink(f0) > 0.01)) v3 = "frame 0 blank";
          else if (!(ink(f1) > 0.01)) v3 = "last frame blank";
          else if (!differ(f0, f1)) v3 = "frames 0 and last are the same";
        }
        // Play starts the animation (the button turns to pause) and a second click stops it.
        var button = document.querySelector(".view3d button");
        button.click();
        if (v3 === "ok" && button.textContent !== "pause") v3 = "play did not start";
        button.click();
        if (v3 === "ok" && button.textContent !== "play") v3 = "pause did not stop";
        var before = V.pixels(); V.rotate(0.7); var after = V.pixels();
        if (v3 === "ok" && !differ(before, after)) v3 = "rotation did not change the picture";
        V.set("mode:0", Math.PI / 2); var m1 = V.pixels(); V.set("mode:0", -Math.PI / 2); var m2 = V.pixels();
        if (v3 === "ok" && !(ink(m1) > 0.01)) v3 = "mode blank";
        if (v3 === "ok" && !differ(m1, m2)) v3 = "the mode does not move";
      }
    } catch (e) { v3 = "error: " + e.message; }
    document.body.setAttribute("data-view3d", v3);
  }
})();
