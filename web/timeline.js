// kerf timeline: one scrubber for every path view. Reads a G-code program into its moves, shows
// the program as a listing, and a slider (arrow keys step, Home/End jump) with play and step
// buttons that report the current move to the plot and mark its line with aria-current.

// The moves of a program: for each line that moves the tool, its index in `lines`, the
// position after it (absolute, the program's units), the motion (G0/G1/G2/G3) and feed.
export function parseProgram(text) {
  const lines = text.replace(/\r/g, '').split('\n');
  if (lines.length && lines[lines.length - 1] === '') lines.pop();
  const moves = [];
  const position = [0, 0, 0];
  let motion = 'G0';
  let feed = null;
  let absolute = true;
  let known = false;
  lines.forEach((line, index) => {
    const code = line.replace(/\([^)]*\)/g, '').replace(/;.*$/, '').toUpperCase();
    const words = [...code.matchAll(/([A-Z])\s*([-+]?\d*\.?\d+)/g)].map(([, letter, number]) => [letter, Number(number)]);
    let moved = false;
    const next = [...position];
    for (const [letter, number] of words) {
      if (letter === 'G') {
        if ([0, 1, 2, 3].includes(number)) motion = `G${number}`;
        if (number === 90) absolute = true;
        if (number === 91) absolute = false;
      } else if (letter === 'F') {
        feed = number;
      } else if ('XYZ'.includes(letter)) {
        const k = 'XYZ'.indexOf(letter);
        next[k] = absolute ? number : next[k] + number;
        moved = true;
      }
    }
    if (!moved || words.some(([l, n]) => l === 'G' && [28, 53, 92, 10].includes(n))) return;
    const length = known ? Math.hypot(next[0] - position[0], next[1] - position[1], next[2] - position[2]) : null;
    position.splice(0, 3, ...next);
    known = true;
    moves.push({ line: index, position: [...position], motion, feed: motion === 'G0' ? null : feed, length });
  });
  return { lines, moves };
}

// A timeline in `container` over `program` (text). `onMove(move)` is called with the current
// move (or null before the first). `label` names the slider ("Timeline: …").
export class Timeline {
  constructor(container, program, { label = 'Timeline', onMove = () => {} } = {}) {
    const { lines, moves } = parseProgram(program);
    this.moves = moves;
    this.onMove = onMove;
    this.root = document.createElement('div');
    this.root.className = 'timeline';
    const controls = document.createElement('div');
    controls.className = 'timeline-controls';
    const button = (text, name, action) => {
      const b = document.createElement('button');
      b.type = 'button';
      b.className = 'secondary small';
      b.textContent = text;
      b.setAttribute('aria-label', name);
      b.addEventListener('click', action);
      controls.append(b);
      return b;
    };
    button('|◀', 'First move', () => this.go(0));
    button('◀', 'Step back', () => this.go(this.index - 1));
    this.play = button('▶', 'Play', () => this.toggle());
    button('▶|', 'Step forward', () => this.go(this.index + 1));
    this.slider = document.createElement('input');
    this.slider.type = 'range';
    this.slider.min = '0';
    this.slider.max = String(Math.max(0, moves.length - 1));
    this.slider.step = '1';
    this.slider.value = '0';
    this.slider.setAttribute('aria-label', `${label} (move along the program)`);
    this.slider.addEventListener('input', () => this.go(Number(this.slider.value)));
    controls.append(this.slider);
    this.readout = document.createElement('output');
    this.readout.className = 'timeline-readout';
    this.listing = document.createElement('ol');
    this.listing.className = 'listing';
    this.listing.setAttribute('aria-label', 'G-code program');
    this.listing.tabIndex = 0;
    const lineOf = new Map(moves.map((m, i) => [m.line, i]));
    this.items = lines.map((text, index) => {
      const li = document.createElement('li');
      li.textContent = text || ' ';
      if (lineOf.has(index)) {
        li.dataset.move = String(lineOf.get(index));
        li.addEventListener('click', () => this.go(lineOf.get(index)));
      }
      return li;
    });
    this.listing.append(...this.items);
    this.root.append(controls, this.readout, this.listing);
    container.append(this.root);
    this.index = -1;
    if (moves.length) this.go(0);
  }

  // Moves the cursor to move `index` (clamped).
  go(index) {
    if (!this.moves.length) return;
    const i = Math.max(0, Math.min(this.moves.length - 1, index));
    const previous = this.moves[this.index];
    if (previous) this.items[previous.line].removeAttribute('aria-current');
    this.index = i;
    this.slider.value = String(i);
    const move = this.moves[i];
    const item = this.items[move.line];
    item.setAttribute('aria-current', 'true');
    this.listing.scrollTop = item.offsetTop - this.listing.clientHeight / 2;
    const [x, y, z] = move.position.map((v) => v.toFixed(3));
    const kind = { G0: 'rapid', G1: 'feed', G2: 'arc cw', G3: 'arc ccw' }[move.motion];
    this.readout.textContent = `Move ${i + 1} of ${this.moves.length}, line ${move.line + 1}: ${kind} to X ${x} Y ${y} Z ${z} mm`
      + `${move.feed ? `, feed ${move.feed} mm/min` : ''}${move.length != null ? `, block ${move.length.toFixed(4)} mm` : ''}`
      + `${move.feed && move.length ? `, ${(move.length / move.feed * 60000).toFixed(2)} ms` : ''}.`;
    this.slider.setAttribute('aria-valuetext', `move ${i + 1} of ${this.moves.length}, line ${move.line + 1}`);
    this.root.dataset.line = String(move.line + 1);
    this.onMove(move);
  }

  // Moves the cursor to the move on program line `number` (1-based), or the last one before it.
  goToLine(number) {
    let found = -1;
    this.moves.forEach((move, i) => { if (move.line <= number - 1) found = i; });
    if (found >= 0) this.go(found);
    this.items[number - 1]?.scrollIntoView({ block: 'nearest' });
  }

  toggle() {
    if (this.timer) {
      clearInterval(this.timer);
      this.timer = null;
      this.play.textContent = '▶';
      this.play.setAttribute('aria-label', 'Play');
      return;
    }
    if (this.index >= this.moves.length - 1) this.go(0);
    this.play.textContent = '⏸';
    this.play.setAttribute('aria-label', 'Pause');
    const step = Math.max(1, Math.round(this.moves.length / 300));
    this.timer = setInterval(() => {
      if (this.index >= this.moves.length - 1 || !this.root.isConnected) this.toggle();
      else this.go(this.index + step);
    }, 40);
  }
}
