// POSIX-style paths relative to the served directory (DIR); the server refuses anything that leaves it.

export function dirname(path: string): string {
  const i = path.lastIndexOf('/');
  return i < 0 ? '' : path.slice(0, i);
}

export function normalize(path: string): string {
  const out: string[] = [];
  for (const part of path.split('/')) {
    if (part === '' || part === '.') continue;
    if (part === '..' && out.length > 0 && out[out.length - 1] !== '..') out.pop();
    else out.push(part);
  }
  return out.join('/');
}

/** `rel` (relative to the folder `dir`) as a path relative to DIR. */
export function join(dir: string, rel: string): string {
  return normalize(dir ? `${dir}/${rel}` : rel);
}

/** The path of `to` relative to the folder `fromDir` (both relative to DIR). */
export function relative(fromDir: string, to: string): string {
  const a = normalize(fromDir).split('/').filter(Boolean);
  const b = normalize(to).split('/').filter(Boolean);
  let i = 0;
  while (i < a.length && i < b.length && a[i] === b[i]) i++;
  return [...a.slice(i).map(() => '..'), ...b.slice(i)].join('/') || '.';
}
