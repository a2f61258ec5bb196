#!/usr/bin/env python3
"""Draw random single-term mutations of the technique shaders, in tests/mutants.txt's format.

tests/mutants.txt holds the mistakes someone thought of; this draws others, to find what a technique's tests miss:

    python3 tools/mutants_sample.py --seed 7 --per-file 2 > /tmp/audit.txt
    bash tools/mutants.sh --list /tmp/audit.txt

Each edit changes one line of a shader that tests/mutants.txt already names: a decimal constant times 1.5, a factor
of a product dropped, `+` / `-` or a comparison flipped, `.rgb` read as `.bgr`. Its tests are the ones the list names
for that file, golden checks left out, so that a survivor is a mistake the technique's own tests do not see (run it
again with `golden.check` to learn whether anything catches it). Some edits change nothing observable (an epsilon's
sign, a clamp that a later clamp repeats): read a survivor before writing a test for it.
"""
import argparse
import collections
import random
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# Tools rather than techniques (their own tests are elsewhere).
SKIP = ('shaders/compare/', 'shaders/debug/', 'shaders/pattern/', 'shaders/accel/', 'shaders/common/magma')
# The path tracers: their tests take minutes a mutation, so they are drawn only with --tracers (and then alone).
TRACERS = ('shaders/pathtrace/', 'shaders/render/', 'shaders/reference/', 'shaders/bake/lightmap')


def listed_tests(listing):
    """Per shader file, the ctest regexes tests/mutants.txt names for it, golden checks taken out."""
    tests = collections.defaultdict(set)
    for line in listing.read_text().splitlines():
        if line.startswith('#') or ';;' not in line:
            continue
        fields = [f.strip() for f in line.split(';;')]
        if not fields[0].startswith('shaders/'):
            continue
        regex = re.sub(r'\|golden(\.check|\.poison)?', '', fields[-2])
        regex = re.sub(r'^golden(\.check|\.poison)?\|?', '', regex)
        if regex:
            tests[fields[0]].add(regex)
    return tests


def ctest_regex(regexes):
    """The alternation of the regexes (| binds loosest, so no parentheses are added), within the 10 groups that
    ctest's regular expressions allow: those with the fewest groups first."""
    kept, groups = [], 0
    for r in sorted(regexes, key=lambda r: (r.count('('), r)):
        if groups + r.count('(') > 9:
            continue
        kept.append(r)
        groups += r.count('(')
    return '|'.join(kept)


def sed_pattern(text):
    return re.sub(r'([\\/.*\[\]^$])', r'\\\1', text)


def sed_replacement(text):
    return text.replace('\\', '\\\\').replace('/', '\\/').replace('&', '\\&')


def edits(code):
    """(new code, what) for each single-term edit of one line of code."""
    for m in re.finditer(r'(?<![\w.])(\d+\.\d+)(?![\w.])', code):
        value = float(m.group(1))
        if value in (0.0, 1.0):
            continue
        scaled = repr(round(value * 1.5, 6))
        yield code[:m.start()] + scaled + code[m.end():], f'constant {m.group(1)} -> {scaled}'
    for m in re.finditer(r'\.rgb\b', code):
        yield code[:m.start()] + '.bgr' + code[m.end():], 'channels rgb -> bgr'
    for m in re.finditer(r'(\w[\w.\[\]]*) \* (\w[\w.\[\]]*)', code):
        yield code[:m.start()] + m.group(1) + code[m.end():], f'factor {m.group(2)} dropped'
    for m in re.finditer(r' (<=|>=|<|>) ', code):
        flipped = {'<': '>=', '>': '<=', '<=': '>', '>=': '<'}[m.group(1)]
        yield code[:m.start()] + f' {flipped} ' + code[m.end():], f'comparison {m.group(1)} -> {flipped}'
    for m in re.finditer(r' ([+-]) ', code):
        other = '-' if m.group(1) == '+' else '+'
        yield code[:m.start()] + f' {other} ' + code[m.end():], f'{m.group(1)} -> {other}'


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--seed', type=int, default=1, help='random sequence (another seed, other edits)')
    parser.add_argument('--per-file', type=int, default=2, help='edits drawn per shader file')
    parser.add_argument('--match', default='', help='only shader files whose path contains this')
    parser.add_argument('--list', type=Path, default=ROOT / 'tests' / 'mutants.txt', help='the list to take tests from')
    parser.add_argument('--tracers', action='store_true',
                        help='draw from the path tracers\' shaders instead (slow tests: minutes a mutation)')
    args = parser.parse_args()
    if args.per_file < 1:
        parser.error('--per-file must be at least 1')
    rng = random.Random(args.seed)
    tests = listed_tests(args.list)
    out = []
    for path in sorted(tests):
        if path.startswith(SKIP) or path.startswith(TRACERS) != args.tracers:
            continue
        if args.match not in path or not (ROOT / path).is_file():
            continue
        lines = (ROOT / path).read_text().splitlines()
        candidates = []
        for line in lines:
            stripped = line.strip()
            if len(stripped) < 12 or stripped.startswith(('//', '#', 'layout')) or lines.count(line) != 1:
                continue  # a line sed can address alone
            code = line.split('//')[0]
            candidates += [(code, new, what) for new, what in edits(code) if new != code]
        rng.shuffle(candidates)
        regex = ctest_regex(tests[path])
        for code, new, what in candidates[:args.per_file]:
            out.append(f'{path} ;; s/^{sed_pattern(code)}/{sed_replacement(new)}/ ;; {regex} ;; '
                       f'audit: {what} (line: {code.strip()[:60]})')
    if not out:
        sys.exit('mutants_sample: no shader of the list matches')
    print('\n'.join(out))


if __name__ == '__main__':
    main()
