// Units of speeds and accelerations, a choice of the page: internal (the
// motion controller's own values), pps (microsteps per second) or rpm
// (revolutions per minute of a motor with the page's full steps per
// revolution). The formulas are the module manual's velocity and
// acceleration calculation; the clock comes from the profile and the
// divisors are the motor's current AP 140, 153 and 154 (docs/ide.md).
/** The axis parameters a conversion needs: microstep resolution, ramp and
 * pulse divisor. */
export const DIVISORS = [140, 153, 154];

const choice = {
  unit: localStorage.getItem("tmclsim-unit") || "internal",
  fullsteps: Number(localStorage.getItem("tmclsim-fullsteps")) || 200,
};
const listeners = [];

export const unit = () => choice.unit;

/** `f` runs whenever the unit or the full steps per revolution change. */
export function onUnits(f) {
  listeners.push(f);
}

/** Every `<span class="unit" data-quantity="…">` of the page names the
 * chosen unit. */
function relabel() {
  for (const s of document.querySelectorAll(".unit[data-quantity]")) s.textContent = unitName(s.dataset.quantity);
}

/** Binds the page's unit selector and full steps input. */
export function unitControls(select, fullsteps) {
  select.value = choice.unit;
  fullsteps.value = String(choice.fullsteps);
  relabel();
  const changed = () => {
    choice.unit = select.value;
    const n = Number(fullsteps.value);
    if (Number.isFinite(n) && n > 0) choice.fullsteps = n;
    localStorage.setItem("tmclsim-unit", choice.unit);
    localStorage.setItem("tmclsim-fullsteps", String(choice.fullsteps));
    relabel();
    for (const f of listeners) f();
  };
  select.addEventListener("change", changed);
  fullsteps.addEventListener("change", changed);
}

/** The unit's name for a quantity ("velocity" or "acceleration"). */
export function unitName(quantity) {
  const per = quantity === "acceleration" ? "/s" : "";
  return { internal: "int", pps: "pps", rpm: "rpm" }[choice.unit] + per;
}

/** Shown value = internal value × factor, or null while a divisor (or the
 * clock) is unknown. `d` holds the motor's AP 140, 153 and 154 by number. */
export function factor(quantity, clock, d) {
  if (choice.unit === "internal") return 1;
  const [mres, rd, pd] = DIVISORS.map((n) => d?.[n]);
  if (!clock || pd == null || (quantity === "acceleration" && rd == null)) return null;
  // v_pps = f_CLK · v / 2^(pulse_div + 16)   (2048 · 32 = 2^16)
  // a_pps = f_CLK² · a / 2^(ramp_div + pulse_div + 29)
  const pps = quantity === "acceleration" ? (clock * clock) / 2 ** (rd + pd + 29) : clock / 2 ** (pd + 16);
  if (choice.unit === "pps") return pps;
  if (mres == null) return null;
  // rps = pps / (microsteps per full step · full steps per revolution)
  return (pps * 60) / (2 ** mres * choice.fullsteps);
}

/** A converted value as text: six significant digits at most. */
export function show(x) {
  return x == null || !Number.isFinite(x) ? "–" : String(Number(x.toPrecision(6)));
}

/** The internal value of `x` typed in the chosen unit (rounded), or null. */
export function toInternal(x, quantity, clock, d) {
  const f = factor(quantity, clock, d);
  return f ? Math.round(x / f) : null;
}

/** The divisors of motor `index` among the reads `signals` → `values`. */
export function divisorsOf(signals, values, index) {
  const d = {};
  signals.forEach((s, i) => {
    if (s.kind === "ap" && s.index === index && DIVISORS.includes(s.number)) d[s.number] = values[i];
  });
  return d;
}

/** Reads of the divisors of motor `index` the profile has. */
export function divisorReads(profile, index) {
  const has = new Set(profile?.axis_parameters.map((r) => r.number) ?? []);
  return DIVISORS.filter((n) => has.has(n)).map((number) => ({ kind: "ap", number, index }));
}

