// Line plots (uPlot) with vertical markers, and the saddle path x_c(t) drawn on a canvas.
import uPlot from 'uplot';

const PALETTE = ['#d9534f', '#3b6fb6', '#2a9d4b', '#8a4fd1', '#e08a00', '#0aa5a5', '#666'];
export const color = (i) => PALETTE[i % PALETTE.length];

/**
 * A plot of series over a shared x: {x, series: [{label, values, color?, points?}], markers:
 * [{x, label, color?}], xLabel, yLabel, zero (a line at y = 0), onCursor(index), onClick(index)}.
 */
export function linePlot(target, { title = '', x, series, markers = [], xLabel = '', yLabel = '', zero = true, width = 420, height = 240, yRange = null, onCursor = null, onClick = null, xRange = null }) {
  const opts = {
    title,
    width: fitWidth(width),
    height,
    scales: { x: { time: false, ...(xRange ? { range: xRange } : {}) }, y: yRange ? { range: yRange } : {} },
    axes: [{ label: xLabel, size: 40 }, { label: yLabel, size: 60 }],
    legend: { live: true },
    series: [
      { label: xLabel || 'x', value: (u, v) => (v == null ? '—' : Number(v.toPrecision(5)).toString()) },
      ...series.map((s, i) => ({
        label: s.label,
        stroke: s.color ?? color(i),
        width: 2,
        points: { show: s.points ?? false, size: 5 },
        value: (u, v) => (v == null ? '—' : Number(v.toPrecision(5)).toString()),
      })),
    ],
    hooks: {
      draw: [
        (u) => {
          const { ctx } = u;
          const { left, top, width: w, height: h } = u.bbox;
          ctx.save();
          if (zero) {
            const y0 = u.valToPos(0, 'y', true);
            if (y0 >= top && y0 <= top + h) {
              ctx.strokeStyle = '#999';
              ctx.lineWidth = 1;
              ctx.beginPath();
              ctx.moveTo(left, y0);
              ctx.lineTo(left + w, y0);
              ctx.stroke();
            }
          }
          ctx.font = `${11 * devicePixelRatio}px sans-serif`;
          ctx.textAlign = 'left'; // uPlot leaves the axes' alignment set: a label starts at its line
          ctx.textBaseline = 'alphabetic';
          markers.forEach((m, i) => {
            if (m.x === undefined || m.x === null || Number.isNaN(m.x)) return;
            const px = u.valToPos(m.x, 'x', true);
            if (px < left || px > left + w) return;
            ctx.strokeStyle = m.color ?? '#444';
            ctx.setLineDash([4 * devicePixelRatio, 3 * devicePixelRatio]);
            ctx.beginPath();
            ctx.moveTo(px, top);
            ctx.lineTo(px, top + h);
            ctx.stroke();
            ctx.setLineDash([]);
            ctx.fillStyle = m.color ?? '#444';
            ctx.fillText(m.label, px + 3, top + 12 * devicePixelRatio * (1 + (i % 3)));
            if (Number.isFinite(m.y)) {
              ctx.beginPath();
              ctx.arc(px, u.valToPos(m.y, 'y', true), 4 * devicePixelRatio, 0, 2 * Math.PI);
              ctx.fill();
            }
          });
          ctx.restore();
        },
      ],
      setCursor: onCursor ? [(u) => onCursor(u.cursor.idx, u)] : [],
      ready: onClick
        ? [
            (u) => {
              u.over.addEventListener('click', () => {
                if (u.cursor.idx !== null && u.cursor.idx !== undefined) onClick(u.cursor.idx, u);
              });
            },
          ]
        : [],
    },
  };
  const data = [Array.from(x), ...series.map((s) => Array.from(s.values, (v) => (Number.isFinite(v) ? v : null)))];
  const plot = new uPlot(opts, data, target);
  plot.markers = markers; // what the plot marks, for the browser tests
  return plot;
}

/**
 * A plot's or viewer's width: `width`, or less on a narrow screen (a phone), so that nothing makes
 * the page scroll sideways: the page's width less the margins and a panel's padding.
 */
export function fitWidth(width, margin = 48) {
  const page = document.documentElement.clientWidth || width + margin;
  return Math.max(200, Math.min(width, page - margin));
}

/**
 * The path of the slice saddle x_c(t) in the slice's (u, v) square (Fig. 4, right): points
 * coloured by the sign of the saddle's value, the face [0, 1]^2 outlined, t1 and t2 marked.
 */
export function saddlePath(canvas, { u, v, saddle, marks = [] }) {
  const ctx = canvas.getContext('2d');
  const size = canvas.width;
  const pad = size * 0.2, scale = (size - 2 * pad) / 1; // [0,1] in the middle, room around it
  const px = (x) => pad + x * scale, py = (y) => size - pad - y * scale;
  ctx.clearRect(0, 0, size, size);
  ctx.strokeStyle = '#999';
  ctx.strokeRect(px(0), py(1), scale, scale);
  ctx.fillStyle = '#666';
  ctx.font = '11px sans-serif';
  ctx.fillText('slice face [0,1]²', px(0), py(1) - 4);
  for (let i = 0; i < u.length; ++i) {
    if (!Number.isFinite(u[i]) || !Number.isFinite(v[i])) continue;
    const x = px(u[i]), y = py(v[i]);
    if (x < 0 || y < 0 || x > size || y > size) continue;
    ctx.fillStyle = saddle[i] >= 0 ? '#222' : '#bbb';
    ctx.beginPath();
    ctx.arc(x, y, 1.8, 0, 2 * Math.PI);
    ctx.fill();
  }
  for (const m of marks) {
    if (!Number.isFinite(m.u) || !Number.isFinite(m.v)) continue;
    ctx.strokeStyle = m.color;
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.arc(px(m.u), py(m.v), 5, 0, 2 * Math.PI);
    ctx.stroke();
    ctx.fillStyle = m.color;
    ctx.fillText(m.label, px(m.u) + 7, py(m.v) - 5);
  }
}

/** Bars of a histogram (log counts) with the isovalue marked; click picks an isovalue. */
export function histogramPlot(target, { min, max, counts, iso, onPick, width = 420, height = 160 }) {
  const n = counts.length;
  const x = Array.from({ length: n }, (_, i) => min + ((i + 0.5) * (max - min)) / n);
  const y = Array.from(counts, (c) => Math.log10(1 + c));
  let current = iso;
  const plot = new uPlot(
    {
      width: fitWidth(width),
      height,
      scales: { x: { time: false } },
      axes: [{ label: 'sample value', size: 36 }, { label: 'log10(1 + count)', size: 50 }],
      legend: { show: false },
      series: [{}, { stroke: '#3b6fb6', fill: 'rgba(59,111,182,0.25)', paths: uPlot.paths.bars({ size: [1, Infinity] }) }],
      hooks: {
        draw: [
          (u) => {
            const p = u.valToPos(current, 'x', true);
            u.ctx.save();
            u.ctx.strokeStyle = '#d9534f';
            u.ctx.lineWidth = 2 * devicePixelRatio;
            u.ctx.beginPath();
            u.ctx.moveTo(p, u.bbox.top);
            u.ctx.lineTo(p, u.bbox.top + u.bbox.height);
            u.ctx.stroke();
            u.ctx.restore();
          },
        ],
        ready: [
          (u) =>
            u.over.addEventListener('click', (e) => {
              const value = u.posToVal(e.offsetX, 'x');
              onPick(value);
            }),
        ],
      },
    },
    [x, y],
    target,
  );
  plot.setIso = (value) => {
    current = value;
    plot.redraw(false);
  };
  return plot;
}
