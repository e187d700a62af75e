// airgun-xl serve: the charts, drawn from the JSON the page holds (never from code built
// out of data). uPlot, vendored beside this file.
"use strict";
(function () {
  const PALETTE = ["#1f5fa8", "#c0392b", "#27ae60", "#8e44ad", "#d68910", "#17a589",
    "#7f8c8d", "#2c3e50"];

  function data(el) {
    return el ? JSON.parse(el.textContent) : null;
  }
  function byId(id) {
    return document.getElementById(id);
  }
  function width() {
    return Math.min(900, document.body.clientWidth - 40);
  }
  // One chart: x and a list of {label, values, colour, points, dash}; logs: distr 3.
  function chart(el, x, lines, xLabel, yLabel, logx, logy) {
    const opts = {
      width: width(), height: 340,
      scales: { x: { time: false, distr: logx ? 3 : 1 }, y: { distr: logy ? 3 : 1 } },
      axes: [{ label: xLabel }, { label: yLabel }],
      series: [{ label: xLabel }].concat(lines.map((s) => ({
        label: s.label, stroke: s.colour, width: s.points ? 0 : 1.5, dash: s.dash,
        points: s.points ? { show: true, size: 6, fill: s.colour, stroke: s.colour }
          : { show: false },
        spanGaps: !s.points,
      }))),
    };
    el.dataset.drawn = String(x.length);
    el.dataset.series = String(lines.length);
    return new uPlot(opts, [x].concat(lines.map((s) => s.values)), el);
  }

  function pulse() {
    const el = byId("pulse");
    const d = data(byId("pulse-data"));
    if (!el || !d) return;
    const lines = [{ label: el.dataset.y, values: d.accel_kg, colour: PALETTE[0] }];
    if (d.band) {
      ["low", "high"].forEach((name, k) => {
        if (d.band[k] !== null) {
          lines.push({ label: "peak " + name + " limit", colour: PALETTE[1], dash: [6, 4],
            values: d.time_ms.map(() => d.band[k]) });
        }
      });
    }
    chart(el, d.time_ms, lines, el.dataset.x, el.dataset.y, false, false);
  }

  function scatter() {
    const el = byId("scatter");
    const d = data(byId("scatter-data"));
    if (!el || !d) return;
    const lines = d.series.map((s, k) => ({
      label: s.name + " (" + s.points + ")", values: s.y, points: true,
      colour: PALETTE[k % PALETTE.length] }));
    const u = chart(el, d.x, lines, d.x_label, d.y_label, d.logx, d.logy);
    const note = byId("scatter-note");
    if (note && d.left_out) {
      note.textContent = d.left_out + " run(s) not drawn: no value" +
        (d.logx || d.logy ? ", or not positive on a log axis" : "") + ".";
    }
    u.over.addEventListener("click", () => {  // a point opens its run
      const i = u.cursor.idx;
      if (i !== null && i !== undefined && d.ids[i] !== undefined) {
        window.location.href = "/shot/" + String(Number(d.ids[i]));
      }
    });
  }

  function overlay() {
    const el = byId("overlay");
    const d = data(byId("overlay-data"));
    if (!el || !d) return;
    const lines = d.y.map((values, k) => ({ label: d.names[k], values: values,
      colour: PALETTE[k % PALETTE.length] }));
    chart(el, d.x, lines, el.dataset.x, el.dataset.y, false, false);
  }

  // Charts of several named lines on one x axis (a law's versions, a verdict's record):
  // the JSON beside each holds x, y (a list a line) and names; a corridor's lines dashed.
  function multi() {
    document.querySelectorAll(".multi-chart").forEach((el) => {
      const d = data(el.nextElementSibling);
      if (!d || !d.x.length) return;
      let colour = -1;  // a line's points (a law's nodes) share its colour
      const lines = d.y.map((values, k) => {
        const points = d.names[k].includes(" nodes, ");
        if (!points) colour += 1;
        return { label: d.names[k], values: values, points: points,
          colour: PALETTE[colour % PALETTE.length],
          dash: d.names[k].startsWith("corridor") ? [6, 4] : undefined };
      });
      chart(el, d.x, lines, el.dataset.x, el.dataset.y, false, false);
    });
  }

  document.addEventListener("DOMContentLoaded", () => {
    pulse();
    scatter();
    overlay();
    multi();
  });
})();
