// airgun-xl serve: the charts, drawn from the JSON the page holds (never from code built
// out of data). uPlot, vendored beside this file.
"use strict";
(function () {
  function data(id) {
    const el = document.getElementById(id);
    return el ? JSON.parse(el.textContent) : null;
  }
  function chart(el, series, x, y, points) {
    const opts = {
      width: Math.min(900, document.body.clientWidth - 40), height: 320,
      scales: { x: { time: false } },
      axes: [{ label: x }, { label: y }],
      series: [{ label: x }, { label: y, stroke: "#1f5fa8",
        points: points ? { show: true, size: 6, fill: "#1f5fa8" } : { show: false },
        width: points ? 0 : 1.5 }],
    };
    el.dataset.drawn = String(series[0].length);
    return new uPlot(opts, series, el);
  }
  function draw() {
    const pulse = data("pulse-data");
    const p = document.getElementById("pulse");
    if (pulse && p) chart(p, [pulse.time_ms, pulse.accel_kg], p.dataset.x, p.dataset.y, false);
    const pts = data("points");
    const s = document.getElementById("scatter");
    if (pts && s) {
      const rows = pts.filter((r) => r[0] !== null && r[1] !== null)
        .sort((a, b) => a[0] - b[0]);
      chart(s, [rows.map((r) => r[0]), rows.map((r) => r[1])], s.dataset.x, s.dataset.y, true);
    }
  }
  document.addEventListener("DOMContentLoaded", draw);
})();
