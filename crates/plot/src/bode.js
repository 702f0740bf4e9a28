// Interactive Bode figures of mms reports: every <div class="mms-bode">
// on the page is drawn from the JSON beside its canvas. Drag across a
// panel to zoom in frequency, double-click to go back to the report's
// view; the readout gives frequency, magnitude and phase of every shown
// trace at the pointer; a legend entry toggles its trace. With the page's
// address ending in #selftest, each figure zooms and toggles by itself and
// the results go into a pre element with the id mms-selftest (the
// browser test reads it).
(function () {
  "use strict";
  var errors = [];
  window.addEventListener("error", function (e) {
    errors.push(String(e.message));
  });

  function niceStep(span, n) {
    var raw = span / Math.max(n, 1);
    var p = Math.pow(10, Math.floor(Math.log10(raw)));
    var m = raw / p;
    return (m <= 1 ? 1 : m <= 2 ? 2 : m <= 5 ? 5 : 10) * p;
  }

  function fmtHz(f) {
    if (f >= 1000) return +(f / 1000).toPrecision(3) + "k";
    return String(+f.toPrecision(3));
  }

  function init(root) {
    var data = JSON.parse(root.querySelector(".mms-data").textContent);
    var canvas = root.querySelector("canvas");
    var readout = root.querySelector(".mms-readout");
    var legend = root.querySelector(".mms-legend");
    var W = 800;
    var H = data.coherence ? 640 : 520;
    var dpr = window.devicePixelRatio || 1;
    canvas.style.width = W + "px";
    canvas.style.height = H + "px";
    canvas.width = Math.round(W * dpr);
    canvas.height = Math.round(H * dpr);
    var ctx = canvas.getContext("2d");
    ctx.scale(dpr, dpr);
    var state = {
      x: data.view.slice(),
      visible: data.traces.map(function () { return true; }),
      draws: 0
    };
    root.mmsState = state;

    var L = 70, R = W - 16, T = 34, gap = 10, bottom = 40;
    var panels = [
      { key: "db", title: "Magnitude [dB]", weight: 3 },
      { key: "deg", title: "Phase [deg]", weight: 2 }
    ];
    if (data.coherence) panels.push({ key: "coh", title: "Coherence", weight: 1.3 });
    var total = panels.reduce(function (s, p) { return s + p.weight; }, 0);
    var avail = H - T - bottom - gap * (panels.length - 1);
    var y0 = T;
    panels.forEach(function (p) {
      p.y = y0;
      p.h = Math.round(avail * p.weight / total);
      y0 += p.h + gap;
    });

    function values(p, i) {
      if (p.key === "coh") return i === 0 ? data.coherence : null;
      return data.traces[i][p.key];
    }
    function lx(f) { return Math.log10(f); }
    function xpx(f) {
      var a = lx(state.x[0]), b = lx(state.x[1]);
      return L + (lx(f) - a) / (b - a) * (R - L);
    }
    function fOf(px) {
      var a = lx(state.x[0]), b = lx(state.x[1]);
      return Math.pow(10, a + (px - L) / (R - L) * (b - a));
    }
    function yRange(p) {
      if (p.key === "coh") return [0, 1];
      var lo = Infinity, hi = -Infinity;
      data.traces.forEach(function (t, i) {
        if (!state.visible[i]) return;
        var v = values(p, i);
        for (var k = 0; k < t.f.length; k++) {
          var f = t.f[k], y = v[k];
          if (f === null || y === null || f < state.x[0] || f > state.x[1]) continue;
          if (y < lo) lo = y;
          if (y > hi) hi = y;
        }
      });
      if (!(lo <= hi)) return p.key === "db" ? [-20, 20] : [-180, 180];
      if (hi - lo < 1e-9) { lo -= 1; hi += 1; }
      var pad = 0.05 * (hi - lo);
      var step = niceStep(hi - lo + 2 * pad, Math.max(2, Math.floor(p.h / 30)));
      return [Math.floor((lo - pad) / step) * step, Math.ceil((hi + pad) / step) * step, step];
    }

    function drawPanel(p, last) {
      var r = yRange(p);
      var step = r[2] || 0.25;
      var ypx = function (v) { return p.y + p.h - (v - r[0]) / (r[1] - r[0]) * p.h; };
      ctx.save();
      ctx.beginPath();
      ctx.rect(L, p.y, R - L, p.h);
      ctx.clip();
      data.bands.forEach(function (b) {
        var a = xpx(Math.max(b[0], state.x[0] / 10)), c = xpx(Math.min(b[1], state.x[1] * 10));
        ctx.fillStyle = "rgba(128,128,128,0.22)";
        ctx.fillRect(a, p.y, c - a, p.h);
      });
      // Grid: decades and their multiples, then the y steps.
      ctx.lineWidth = 1;
      var d0 = Math.floor(lx(state.x[0])), d1 = Math.ceil(lx(state.x[1]));
      for (var d = d0; d <= d1; d++) {
        for (var m = 1; m < 10; m++) {
          var f = m * Math.pow(10, d);
          if (f < state.x[0] || f > state.x[1]) continue;
          ctx.strokeStyle = m === 1 ? "#c8c8c8" : "#ececec";
          ctx.beginPath();
          ctx.moveTo(Math.round(xpx(f)) + 0.5, p.y);
          ctx.lineTo(Math.round(xpx(f)) + 0.5, p.y + p.h);
          ctx.stroke();
        }
      }
      ctx.strokeStyle = "#c8c8c8";
      for (var v = r[0]; v <= r[1] + 1e-9; v += step) {
        ctx.beginPath();
        ctx.moveTo(L, Math.round(ypx(v)) + 0.5);
        ctx.lineTo(R, Math.round(ypx(v)) + 0.5);
        ctx.stroke();
      }
      // Data first, models over them.
      data.traces.forEach(function (t, i) {
        var v = values(p, i);
        if (!state.visible[i] || !v) return;
        ctx.strokeStyle = ctx.fillStyle = t.color;
        if (t.style === "points") {
          for (var k = 0; k < t.f.length; k++) {
            if (t.f[k] === null || v[k] === null) continue;
            ctx.beginPath();
            ctx.arc(xpx(t.f[k]), ypx(v[k]), 2, 0, 2 * Math.PI);
            ctx.fill();
          }
        }
      });
      data.traces.forEach(function (t, i) {
        var v = values(p, i);
        if (!state.visible[i] || !v || t.style === "points") return;
        ctx.strokeStyle = t.color;
        ctx.lineWidth = 1.5;
        ctx.setLineDash(t.style === "dashed" ? [6, 4] : t.style === "dotted" ? [2, 3] : []);
        ctx.beginPath();
        var pen = false;
        for (var k = 0; k < t.f.length; k++) {
          if (t.f[k] === null || v[k] === null) { pen = false; continue; }
          if (pen) ctx.lineTo(xpx(t.f[k]), ypx(v[k]));
          else ctx.moveTo(xpx(t.f[k]), ypx(v[k]));
          pen = true;
        }
        ctx.stroke();
        ctx.setLineDash([]);
      });
      ctx.restore();
      // Frame, tick labels, title.
      ctx.strokeStyle = "#222";
      ctx.lineWidth = 1;
      ctx.strokeRect(L + 0.5, p.y + 0.5, R - L - 1, p.h - 1);
      ctx.fillStyle = "#222";
      ctx.font = "11px DejaVu Sans, Verdana, Arial, sans-serif";
      ctx.textAlign = "right";
      for (var w = r[0]; w <= r[1] + 1e-9; w += step) {
        ctx.fillText(String(+w.toPrecision(4)), L - 6, ypx(w) + 4);
      }
      if (last) {
        ctx.textAlign = "center";
        var labelled = 0;
        for (var e = d0; e <= d1; e++) {
          var g = Math.pow(10, e);
          if (g >= state.x[0] && g <= state.x[1]) {
            ctx.fillText(fmtHz(g), xpx(g), p.y + p.h + 16);
            labelled++;
          }
        }
        if (labelled < 2) {
          // A short range: its 2 and 5 multiples too.
          for (var e2 = d0; e2 <= d1; e2++) {
            [2, 5].forEach(function (m2) {
              var g2 = m2 * Math.pow(10, e2);
              if (g2 >= state.x[0] && g2 <= state.x[1]) ctx.fillText(fmtHz(g2), xpx(g2), p.y + p.h + 16);
            });
          }
        }
        ctx.fillText("Frequency [Hz]", (L + R) / 2, p.y + p.h + 34);
      }
      ctx.save();
      ctx.translate(16, p.y + p.h / 2);
      ctx.rotate(-Math.PI / 2);
      ctx.textAlign = "center";
      ctx.fillText(p.title, 0, 0);
      ctx.restore();
    }

    function draw(cursor, select) {
      ctx.fillStyle = "#fff";
      ctx.fillRect(0, 0, W, H);
      ctx.fillStyle = "#222";
      ctx.font = "15px DejaVu Sans, Verdana, Arial, sans-serif";
      ctx.textAlign = "center";
      ctx.fillText(data.title, (L + R) / 2, 20);
      panels.forEach(function (p, k) { drawPanel(p, k === panels.length - 1); });
      var bottomY = panels[panels.length - 1].y + panels[panels.length - 1].h;
      if (cursor !== undefined) {
        ctx.strokeStyle = "rgba(0,0,0,0.5)";
        ctx.beginPath();
        ctx.moveTo(cursor + 0.5, T);
        ctx.lineTo(cursor + 0.5, bottomY);
        ctx.stroke();
      }
      if (select) {
        ctx.fillStyle = "rgba(0,114,178,0.15)";
        ctx.fillRect(Math.min(select[0], select[1]), T, Math.abs(select[1] - select[0]), bottomY - T);
      }
      state.draws++;
    }

    function nearest(f, fs) {
      var best = -1, dist = Infinity;
      for (var k = 0; k < fs.length; k++) {
        if (fs[k] === null) continue;
        var d = Math.abs(lx(fs[k]) - lx(f));
        if (d < dist) { dist = d; best = k; }
      }
      return best;
    }

    function showReadout(px) {
      var f = fOf(px);
      var parts = ["f = " + fmtHz(f) + " Hz"];
      data.traces.forEach(function (t, i) {
        if (!state.visible[i]) return;
        var k = nearest(f, t.f);
        if (k < 0 || t.db[k] === null) return;
        parts.push((t.label || "trace " + (i + 1)) + ": " + t.db[k].toFixed(2) + " dB, " +
          t.deg[k].toFixed(1) + "\u00b0 (at " + fmtHz(t.f[k]) + " Hz)");
      });
      readout.textContent = parts.join("  |  ");
    }

    data.traces.forEach(function (t, i) {
      if (!t.label) return;
      var item = document.createElement("span");
      item.className = "mms-legend-item";
      item.style.cssText = "cursor:pointer;margin-right:1.2em;white-space:nowrap";
      var sw = document.createElement("span");
      sw.style.cssText = "display:inline-block;width:1.6em;height:0.35em;vertical-align:middle;margin-right:0.4em;background:" + t.color;
      item.appendChild(sw);
      item.appendChild(document.createTextNode(t.label));
      item.addEventListener("click", function () {
        state.visible[i] = !state.visible[i];
        item.style.opacity = state.visible[i] ? "1" : "0.35";
        draw();
      });
      legend.appendChild(item);
    });

    var dragFrom = null;
    function localX(e) {
      var b = canvas.getBoundingClientRect();
      return (e.clientX - b.left) * W / b.width;
    }
    canvas.addEventListener("mousedown", function (e) {
      var x = localX(e);
      if (x >= L && x <= R) dragFrom = x;
    });
    canvas.addEventListener("mousemove", function (e) {
      var x = Math.min(Math.max(localX(e), L), R);
      draw(x, dragFrom !== null ? [dragFrom, x] : undefined);
      showReadout(x);
    });
    canvas.addEventListener("mouseup", function (e) {
      if (dragFrom === null) return;
      var x = Math.min(Math.max(localX(e), L), R);
      if (Math.abs(x - dragFrom) > 4) {
        var a = fOf(Math.min(x, dragFrom)), b = fOf(Math.max(x, dragFrom));
        state.x = [a, b];
      }
      dragFrom = null;
      draw();
    });
    canvas.addEventListener("mouseleave", function () { draw(); });
    canvas.addEventListener("dblclick", function () {
      state.x = data.view.slice();
      draw();
    });
    draw();
    return { root: root, canvas: canvas, legend: legend, W: W, H: H, L: L, R: R, panels: panels };
  }

  var figures = [];
  document.querySelectorAll(".mms-bode").forEach(function (root) {
    try {
      figures.push(init(root));
    } catch (e) {
      errors.push(String(e));
    }
  });

  if (window.location.hash === "#selftest") {
    var results = figures.map(function (fig) {
      var st = fig.root.mmsState;
      var c = fig.canvas.getContext("2d").getImageData(0, 0, fig.canvas.width, fig.canvas.height).data;
      var inked = 0;
      for (var k = 0; k < c.length; k += 4) if (c[k] < 200 || c[k + 1] < 200 || c[k + 2] < 200) inked++;
      var before = st.x.slice();
      var b = fig.canvas.getBoundingClientRect();
      var p = fig.panels[0];
      var at = function (fx) {
        return { clientX: b.left + (fig.L + fx * (fig.R - fig.L)) * b.width / fig.W,
                 clientY: b.top + (p.y + p.h / 2) * b.height / fig.H, bubbles: true };
      };
      fig.canvas.dispatchEvent(new MouseEvent("mousedown", at(0.3)));
      fig.canvas.dispatchEvent(new MouseEvent("mousemove", at(0.6)));
      fig.canvas.dispatchEvent(new MouseEvent("mouseup", at(0.6)));
      var after = st.x.slice();
      var readout = fig.root.querySelector(".mms-readout").textContent;
      var first = fig.legend.querySelector(".mms-legend-item");
      if (first) first.click();
      var toggled = !st.visible[0];
      return { inked: inked, pixels: c.length / 4, before: before, after: after,
               readout: readout, toggled: toggled, draws: st.draws };
    });
    var pre = document.createElement("pre");
    pre.id = "mms-selftest";
    pre.textContent = JSON.stringify({ errors: errors, figures: results });
    document.body.appendChild(pre);
  }
})();
