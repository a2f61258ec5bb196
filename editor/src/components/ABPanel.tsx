// A/B: two graphs or variants (or the current edits) compared by the server (`vitrine compare`'s metrics and
// FLIP map), shown as a split view with a slider.
import { useState } from 'react';
import { compare, fetchImage, type CompareResult, type GraphListEntry, type GraphRef } from '../api';
import { isObject, type Json } from '../graph/types';

const CURRENT = '(current edits)';

const blobUrl = async (url: string): Promise<string> => URL.createObjectURL(await fetchImage(url));

function metric(v: Json | undefined): string {
  return typeof v === 'number' ? String(Number(v.toPrecision(5))) : v === null ? '∞' : '–';
}

export function ABPanel(props: {
  graphs: GraphListEntry[];
  current?: GraphRef;
  defaultA?: string;
  onClose(): void;
  onBusy(busy: boolean): void;
}) {
  const { graphs, current, defaultA, onClose, onBusy } = props;
  const options = [...(current ? [CURRENT] : []), ...graphs.map((g) => g.path)];
  const [a, setA] = useState(defaultA ?? options[0] ?? '');
  const [b, setB] = useState(current ? CURRENT : (options[1] ?? ''));
  const [split, setSplit] = useState(50);
  const [result, setResult] = useState<{ a: string; b: string; flip: string; metrics: CompareResult['metrics'] }>();
  const [error, setError] = useState<string>();
  const [running, setRunning] = useState(false);

  const ref = (p: string): GraphRef => (p === CURRENT && current ? current : { graph: p });

  const run = async () => {
    setRunning(true);
    onBusy(true);
    setError(undefined);
    try {
      const r = await compare(ref(a), ref(b), { width: 480, height: 270 });
      const [ia, ib, flip] = await Promise.all([blobUrl(r.images.a), blobUrl(r.images.b), blobUrl(r.images.flip)]);
      setResult({ a: ia, b: ib, flip, metrics: r.metrics });
    } catch (e) {
      setError((e as Error).message);
    } finally {
      setRunning(false);
      onBusy(false);
    }
  };

  const pair = result && Array.isArray(result.metrics.pairs) && isObject(result.metrics.pairs[0]) ? result.metrics.pairs[0] : undefined;
  const flip = pair && isObject(pair.flip) ? pair.flip : undefined;

  return (
    <div className="modal" onClick={onClose}>
      <div className="ab" data-testid="ab" onClick={(e) => e.stopPropagation()}>
        <div className="viewer-bar">
          <label>
            A{' '}
            <select data-testid="ab-a" value={a} onChange={(e) => setA(e.target.value)}>
              {options.map((o) => (
                <option key={o}>{o}</option>
              ))}
            </select>
          </label>
          <label>
            B{' '}
            <select data-testid="ab-b" value={b} onChange={(e) => setB(e.target.value)}>
              {options.map((o) => (
                <option key={o}>{o}</option>
              ))}
            </select>
          </label>
          <button data-testid="ab-run" onClick={run} disabled={running}>
            {running ? 'Comparing…' : 'Compare'}
          </button>
          <button onClick={onClose}>Close</button>
        </div>
        {error && <div className="param-error">{error}</div>}
        {result && (
          <div className="ab-body">
            <div className="split">
              <img data-testid="ab-image-a" src={result.a} alt="A" />
              <img data-testid="ab-image-b" src={result.b} alt="B" style={{ clipPath: `inset(0 0 0 ${split}%)` }} />
              <div className="split-line" style={{ left: `${split}%` }} />
              <span className="split-label left">A</span>
              <span className="split-label right">B</span>
            </div>
            <input type="range" min={0} max={100} data-testid="ab-slider" value={split} onChange={(e) => setSplit(Number(e.target.value))} />
            <div className="ab-side">
              <figure>
                <img data-testid="ab-flip" src={result.flip} alt="FLIP" />
                <figcaption>FLIP error (A vs B)</figcaption>
              </figure>
              <table className="metrics">
                <tbody>
                  <tr>
                    <th>FLIP mean</th>
                    <td data-testid="ab-metric-flip">{metric(flip?.mean)}</td>
                  </tr>
                  <tr>
                    <th>PSNR (dB)</th>
                    <td data-testid="ab-metric-psnr">{metric(pair?.psnr)}</td>
                  </tr>
                  <tr>
                    <th>SSIM</th>
                    <td data-testid="ab-metric-ssim">{metric(pair?.ssim)}</td>
                  </tr>
                </tbody>
              </table>
            </div>
          </div>
        )}
      </div>
    </div>
  );
}
