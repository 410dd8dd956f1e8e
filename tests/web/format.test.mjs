// The page's number formats and axis ticks, in node without a browser: ticks at 1-2-5 steps inside the
// range, labels with the decimals the step needs, durations as the solver's figures write them.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { niceStep, niceTicks, tickLabel } from '../../server/web/chart.js';
import { humanDuration } from '../../server/web/format.js';

test('ticks are multiples of a 1-2-5 step inside the range', () => {
  assert.equal(niceStep(0.0615), 0.05);
  assert.equal(niceStep(0.18), 0.2);
  assert.equal(niceStep(8), 10);
  const ticks = niceTicks(0, 0.3075, 5);
  assert.deepEqual(ticks.map((t) => tickLabel(t, 0.05)), ['0', '0.05', '0.1', '0.15', '0.2', '0.25', '0.3']);
  assert.deepEqual(niceTicks(0, 1, 10).map((t) => tickLabel(t, 0.1)),
    ['0', '0.1', '0.2', '0.3', '0.4', '0.5', '0.6', '0.7', '0.8', '0.9', '1']);
  assert.deepEqual(niceTicks(-0.23, 0.41, 6).map((t) => tickLabel(t, 0.1)), ['-0.2', '-0.1', '0', '0.1', '0.2', '0.3', '0.4']);
  assert.deepEqual(niceTicks(1, 1, 5), []);
});

test('durations read as a person writes them', () => {
  assert.equal(humanDuration(2.5), '2.5 s');
  assert.equal(humanDuration(0.25), '0.25 s');
  assert.equal(humanDuration(45), '45 s');
  assert.equal(humanDuration(600), '10 min');
  assert.equal(humanDuration(90), '1 min 30 s');
  assert.equal(humanDuration(3600), '1 h');
  assert.equal(humanDuration(8100), '2 h 15 min');
  assert.equal(humanDuration(null), '—');
});
