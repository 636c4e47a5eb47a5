// Plots: numeric properties picked in the inspector (its ∿ button), drawn live with uPlot from the
// `set` entries of the `changes` events. The x axis is the simulated time of each batch by default; the
// wall clock is the choice for a state that is not stepped (the vsd-web tool showing a file), where the
// simulated time stands still while edits come in. When the simulated time goes back (the timeline was
// scrubbed, or forked), the plot starts over from there.

import uPlot from 'uplot';
import { get } from './api.js';
import { on } from './bus.js';

const MAX_POINTS = 3000;
const stepped = uPlot.paths.stepped({ align: 1 });
const pane = document.getElementById('plots');
const hint = document.getElementById('plots-hint');
const axisSelect = document.getElementById('plots-axis');
let simTime = 0;       // of the newest batch

const series = [];     // {id, property, label, last}
let xs = [];
let ys = [];           // one array per series, aligned with xs
let chart = null;
let legend = null;
let drawQueued = false;

function numeric(value) {
  if (typeof value === 'boolean') return value ? 1 : 0;
  return typeof value === 'number' ? value : null;
}

function rebuild() {
  chart?.destroy();
  chart = null;
  legend?.remove();
  hint.hidden = series.length > 0;
  if (!series.length) return;
  legend = document.createElement('ul');
  legend.className = 'plot-series';
  series.forEach((s, i) => {
    const li = document.createElement('li');
    li.textContent = `${s.label} `;
    const remove = document.createElement('button');
    remove.textContent = '✕';
    remove.title = 'stop plotting';
    remove.addEventListener('click', () => {
      series.splice(i, 1);
      ys.splice(i, 1);
      rebuild();
    });
    li.append(remove);
    legend.append(li);
  });
  pane.append(legend);
  const colors = ['#1f77b4', '#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#8c564b'];
  chart = new uPlot({
    width: Math.max(pane.clientWidth - 20, 300),
    height: Math.max(pane.clientHeight - 80, 200),
    // Stepped: a property keeps its value until the next change.
    series: [{}, ...series.map((s, i) => ({ label: s.label, stroke: colors[i % colors.length], spanGaps: true,
                                             paths: stepped }))],
    scales: { x: { time: axisSelect.value === 'wall' } },
    axes: [{ label: axisSelect.value === 'wall' ? '' : 'simulated time (s)' }, {}],
  }, [xs, ...ys], pane);
}

function draw() {
  if (drawQueued || !chart) return;
  drawQueued = true;
  requestAnimationFrame(() => {
    drawQueued = false;
    chart?.setData([xs, ...ys]);
  });
}

// One point per series: each carries its last value forward, so the lines stay aligned on one x.
function push() {
  const x = axisSelect.value === 'wall' ? Date.now() / 1000 : simTime;
  if (xs.length && x < xs[xs.length - 1]) {
    xs = [];
    ys = ys.map(() => []);
  }
  xs.push(x);
  series.forEach((s, i) => ys[i].push(s.last));
  if (xs.length > MAX_POINTS) {
    xs = xs.slice(-MAX_POINTS);
    ys = ys.map((y) => y.slice(-MAX_POINTS));
  }
  draw();
}

on('plot', async ({ id, property, label }) => {
  if (series.some((s) => s.id === id && s.property === property)) return;
  let last = null;
  try {
    simTime = (await get('/api/info')).time ?? simTime;
    const info = await get('/api/instance', { id });
    last = numeric(info.properties.find((p) => p.name === property)?.value);
  } catch { /* plotted from its next change on */ }
  series.push({ id, property, label, last });
  ys.push(xs.map(() => null));
  rebuild();
  push();
  document.querySelector('[data-tab="plots"]')?.click();
});

on('changes', (batch) => {
  if (typeof batch.time === 'number') simTime = batch.time;
  if (!series.length) return;
  let touched = false;
  for (const set of batch.set || []) {
    for (const s of series) {
      if (s.id === set.id && s.property === set.property) {
        s.last = numeric(set.value);
        touched = true;
      }
    }
  }
  if (touched) push();
});

on('tab', (name) => name === 'plots' && chart && chart.setSize({
  width: Math.max(pane.clientWidth - 20, 300), height: Math.max(pane.clientHeight - 80, 200) }));

axisSelect.addEventListener('change', () => {
  xs = [];
  ys = ys.map(() => []);
  rebuild();
  if (series.length) push();
});

export function plotted() {
  return series.map((s, i) => ({ id: s.id, property: s.property, axis: axisSelect.value, x: xs.at(-1),
                                 points: ys[i].filter((v) => v !== null).length }));
}
