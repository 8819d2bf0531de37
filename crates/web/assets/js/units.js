// Units of speeds and accelerations, a choice of the page: internal (the
// values as the module takes them), pps (microsteps per second) or rpm
// (revolutions per minute of a motor with the page's full steps per
// revolution). How a module's values convert comes from its profile
// (docs/ide.md): each velocity and acceleration row names its `quantity`
// and the units it is in (`quantity_units`), and `conversion` names the
// axis parameters the conversion reads from the motor, read with the
// values:
//   tmc429    the TMC429's internal units: the module manual's velocity and
//             acceleration calculation with the profile's clock and the
//             motor's pulse and ramp divisors (AP 154, 153)
//   pps       microsteps per second (per second²) as written
//   sixpoint  as the motor's unit mode (AP 255) says: 1 pps as written,
//             0 the TMC5130/TMC5160's registers (v·f_CLK/2^24 pps,
//             a·f_CLK²/2^41 pps²)
//   tmc4361a  as the motor's unit mode (AP 255) says: 1 pps as written,
//             0 the TMC4361A's registers (24.8 and 22.2 fixed point:
//             v/256 pps, a/4 pps²)
// rpm needs the microstep resolution (AP 140) besides.

const choice = {
  unit: localStorage.getItem("tmclsim-unit") || "internal",
  fullsteps: Number(localStorage.getItem("tmclsim-fullsteps")) || 200,
};
const listeners = [];

// The module shown and the last conversion reads of its motor: what the
// page's unit labels say in internal units on a module whose unit mode
// chooses them.
const shown = { profile: null, reads: {} };

export const unit = () => choice.unit;

/** `f` runs whenever the unit or the full steps per revolution change (or
 * what an internal value's unit is, with the motor's unit mode). */
export function onUnits(f) {
  listeners.push(f);
}

/** Every `<span class="unit" data-quantity="…">` of the page names the
 * chosen unit of the module's speeds (AP 2, 4: its motion units). */
function relabel() {
  const units = shown.profile?.motion_units;
  for (const s of document.querySelectorAll(".unit[data-quantity]")) s.textContent = unitName(s.dataset.quantity, units, shown.reads);
}

function changed() {
  relabel();
  for (const f of listeners) f();
}

/** Binds the page's unit selector and full steps input. */
export function unitControls(select, fullsteps) {
  select.value = choice.unit;
  fullsteps.value = String(choice.fullsteps);
  relabel();
  const change = () => {
    choice.unit = select.value;
    const n = Number(fullsteps.value);
    if (Number.isFinite(n) && n > 0) choice.fullsteps = n;
    localStorage.setItem("tmclsim-unit", choice.unit);
    localStorage.setItem("tmclsim-fullsteps", String(choice.fullsteps));
    changed();
  };
  select.addEventListener("change", change);
  fullsteps.addEventListener("change", change);
}

/** The module the panels now show; its labels until its motor is read. */
export function showModule(profile) {
  shown.profile = profile;
  shown.reads = {};
  relabel();
}

/** The conversion reads of the shown motor (the motion panel's, with every
 * sample): when they change what an internal value's unit is, the labels
 * and the panels follow. */
export function learn(reads) {
  const units = shown.profile?.motion_units;
  const before = ["velocity", "acceleration"].map((q) => unitName(q, units, shown.reads)).join();
  shown.reads = reads;
  if (["velocity", "acceleration"].map((q) => unitName(q, units, reads)).join() !== before) changed();
}

/** The sixPoint unit mode among the reads: true for the chip's registers
 * (AP 255 = 0), false for pps (also on a module without a unit mode, such
 * as the eight-point modules), null while not read. */
function registers(profile, d) {
  const n = profile?.conversion?.unit_mode;
  if (n == null) return false;
  const mode = d?.[n];
  return mode == null ? null : mode === 0;
}

/** What an internal value of these units is: "int" (the motion
 * controller's units) or "pps"; null while the unit mode is not read. */
function internalName(units, d) {
  if (units === "pps") return "pps";
  if (units !== "sixpoint" && units !== "tmc4361a") return "int";
  const r = registers(shown.profile, d);
  return r == null ? null : r ? "int" : "pps";
}

/** The unit's name for a quantity ("velocity" or "acceleration") of
 * `units` (a row's `quantity_units`; the TMC429's when not given), with the
 * motor's conversion reads `d` (for the unit mode). */
export function unitName(quantity, units = "tmc429", d = shown.reads) {
  const per = quantity === "acceleration" ? "/s" : "";
  const name = choice.unit === "internal" ? internalName(units, d) : choice.unit;
  return name == null ? "–" : name + per;
}

/** Shown value = the module's value × factor, or null while a read it
 * needs (or the clock) is unknown. `d` holds the motor's conversion reads
 * by number (the profile's `conversion`); `units` is the row's
 * `quantity_units` (the profile's `motion_units` for a speed of ROR, ROL,
 * MVP). */
export function factor(quantity, units, profile, d) {
  if (choice.unit === "internal") return 1;
  const clock = profile?.motion_clock_hz;
  const c = profile?.conversion ?? {};
  const read = (role) => (c[role] == null ? null : (d?.[c[role]] ?? null));
  let pps;
  if (units === "pps") {
    pps = 1;
  } else if (units === "sixpoint") {
    const r = registers(profile, d);
    if (r == null || !clock) return null;
    // v_pps = v · f_CLK / 2^24, a_pps = a · f_CLK² / 2^41 (AP 255 = 0)
    pps = !r ? 1 : quantity === "acceleration" ? (clock * clock) / 2 ** 41 : clock / 2 ** 24;
  } else if (units === "tmc4361a") {
    const r = registers(profile, d);
    if (r == null) return null;
    // 24.8 and 22.2 fixed point (AP 255 = 0)
    pps = !r ? 1 : quantity === "acceleration" ? 1 / 4 : 1 / 256;
  } else {
    const [rd, pd] = [read("ramp_divisor"), read("pulse_divisor")];
    if (!clock || pd == null || (quantity === "acceleration" && rd == null)) return null;
    // v_pps = f_CLK · v / 2^(pulse_div + 16)   (2048 · 32 = 2^16)
    // a_pps = f_CLK² · a / 2^(ramp_div + pulse_div + 29)
    pps = quantity === "acceleration" ? (clock * clock) / 2 ** (rd + pd + 29) : clock / 2 ** (pd + 16);
  }
  if (choice.unit === "pps") return pps;
  const mres = read("microsteps");
  if (mres == null) return null;
  // rps = pps / (microsteps per full step · full steps per revolution)
  return (pps * 60) / (2 ** mres * choice.fullsteps);
}

/** A converted value as text: six significant digits at most. */
export function show(x) {
  return x == null || !Number.isFinite(x) ? "–" : String(Number(x.toPrecision(6)));
}

/** The module's value of `x` typed in the chosen unit (rounded), or null. */
export function toInternal(x, quantity, units, profile, d) {
  const f = factor(quantity, units, profile, d);
  return f ? Math.round(x / f) : null;
}

/** The axis parameter numbers a conversion reads (the profile's
 * `conversion`). */
export function conversionNumbers(profile) {
  return Object.values(profile?.conversion ?? {});
}

/** The conversion reads of motor `index` among the reads `signals` →
 * `values`, by number. */
export function conversionOf(profile, signals, values, index) {
  const numbers = conversionNumbers(profile);
  const d = {};
  signals.forEach((s, i) => {
    if (s.kind === "ap" && s.index === index && numbers.includes(s.number)) d[s.number] = values[i];
  });
  return d;
}

/** Reads of the conversion parameters of motor `index`. */
export function conversionReads(profile, index) {
  return conversionNumbers(profile).map((number) => ({ kind: "ap", number, index }));
}

/** What a conversion waits for, in words: "AP 140, 153, 154". */
export function conversionNames(profile) {
  const n = conversionNumbers(profile);
  return n.length ? `AP ${n.join(", ")}` : "no parameters";
}
