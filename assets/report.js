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
    var W = 760, H = 320, L = 70, R = 16, T = 28, B = 44;
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
      text(svg, W / 2, 18, spec.title, "middle", "title");
      ticks(view[0], view[1], 8).forEach(function (v) {
        el("line", { x1: sx(v), x2: sx(v), y1: T, y2: H - B, "class": "grid" }, svg);
        text(svg, sx(v), H - B + 16, fmt(v), "middle", "tick");
      });
      ticks(ylo, yhi, 6).forEach(function (v) {
        el("line", { x1: L, x2: W - R, y1: sy(v), y2: sy(v), "class": "grid" }, svg);
        text(svg, L - 6, sy(v) + 4, fmt(v), "end", "tick");
      });
      (spec.markers || []).forEach(function (m) {
        if (m >= view[0] && m <= view[1]) el("line", { x1: sx(m), x2: sx(m), y1: T, y2: H - B, "class": "marker" }, svg);
      });
      el("rect", { x: L, y: T, width: W - L - R, height: H - T - B, "class": "frame" }, svg);
      text(svg, (L + W - R) / 2, H - 8, spec.xlabel, "middle", "label");
      var yl = text(svg, 14, (T + H - B) / 2, spec.ylabel, "middle", "label");
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
        el("line", { x1: W - R - 170, x2: W - R - 152, y1: ly - 4, y2: ly - 4, stroke: COLORS[k % COLORS.length], "stroke-width": 2 }, svg);
        text(svg, W - R - 148, ly, s.name, "start", "legend");
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
  function data(node) {
    return JSON.parse(node.querySelector("script[type='application/json']").textContent);
  }
  document.querySelectorAll("figure.plot").forEach(function (f) { Chart(f, data(f)); });
  document.querySelectorAll(".animation").forEach(function (a) { Animation(a, data(a)); });
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
    } catch (e) { verdict = "error: " + e.message; }
    document.body.setAttribute("data-selftest", verdict);
  }
})();
