// A small line plot of one metric over the run, on a canvas, with a marker
// at the step shown.
export function drawPlot(canvas, series, currentStep, label) {
  const dpr = window.devicePixelRatio || 1;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
  }
  const g = canvas.getContext('2d');
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  g.clearRect(0, 0, w, h);
  g.font = '11px system-ui, sans-serif';
  if (!series || series.steps.length === 0) {
    g.fillStyle = '#8890a0';
    g.fillText(label || 'no metric recorded', 8, 16);
    return;
  }
  const n = series.steps.length;
  const values = new Float64Array(n);
  let lo = Infinity, hi = -Infinity;
  for (let i = 0; i < n; ++i) {
    values[i] = series.sum[i] / series.count[i];
    if (Number.isFinite(values[i])) { lo = Math.min(lo, values[i]); hi = Math.max(hi, values[i]); }
  }
  if (!(hi > lo)) { hi = lo + 1; lo -= 1; }
  const s0 = series.steps[0], s1 = Math.max(series.steps[n - 1], s0 + 1);
  const left = 48, right = w - 8, top = 6, bottom = h - 14;
  const X = (s) => left + (s - s0) / (s1 - s0) * (right - left);
  const Y = (v) => bottom - (v - lo) / (hi - lo) * (bottom - top);
  g.strokeStyle = '#3a404a';
  g.strokeRect(left, top, right - left, bottom - top);
  g.fillStyle = '#aab';
  g.fillText(hi.toPrecision(4), 2, top + 9);
  g.fillText(lo.toPrecision(4), 2, bottom);
  g.fillText(`step ${s0}`, left, h - 2);
  g.fillText(`${s1}`, right - 30, h - 2);
  g.strokeStyle = '#5ec4ff';
  g.lineWidth = 1.5;
  g.beginPath();
  for (let i = 0; i < n; ++i) {
    if (!Number.isFinite(values[i])) continue;
    if (i === 0) g.moveTo(X(series.steps[i]), Y(values[i]));
    else g.lineTo(X(series.steps[i]), Y(values[i]));
  }
  g.stroke();
  if (currentStep !== undefined) {
    g.strokeStyle = '#ffd34d';
    g.beginPath();
    g.moveTo(X(currentStep), top);
    g.lineTo(X(currentStep), bottom);
    g.stroke();
  }
}
