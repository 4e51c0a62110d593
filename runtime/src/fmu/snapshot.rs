//! FMU states: deep copies of the instance's [`Core`] (boxed; the instance keeps the list of
//! its own) for fmi2GetFMUstate/SetFMUstate and their checked byte format for
//! fmi2SerializeFMUstate/DeSerializeFMUstate.
//!
//! Byte format, little endian: magic `BOOMSIM\0`, format version (u32), GUID (u32 length +
//! UTF-8), payload length (u64), payload, CRC-32 of everything before it (u32). The payload holds
//! the FMI version and interface of the instance that took the state, the state machine state,
//! times, the Clock's activations made, every variable value, the input derivatives and the model's own state. Any mismatch
//! (size, GUID, format version, checksum, FMI version, interface, value types) is refused with a
//! reason, and so is a state machine state that no instance of that FMI version and interface
//! can save (FMI 2.0 has no Intermediate Update Mode, and no state is taken inside one),
//! and so is a well-formed state whose values fmi2SetReal would refuse (a non-finite number, a
//! parameter or input outside its range, inconsistent times): a checksum only proves the bytes
//! were not damaged, not that they were written by this FMU.

use super::driver::Driven;
use super::instance::{activation, in_range, Core, TOLERANCE_RANGE};
use super::log::num;
use super::machine::{Interface, Mode};
use super::model::Model;
use super::variables::{Causality, Value, Values, Variable};
use super::version::Version;

const MAGIC: &[u8; 8] = b"BOOMSIM\0";
/// Version of the byte format; bump it when the layout changes.
pub const FORMAT_VERSION: u32 = 6;

/// Who took a state: the FMI version and interface of the instance.
pub type Origin = (Version, Interface);

/// Serialises a core that an instance of `origin` took into the checked byte format.
pub fn serialize<M: Model>(core: &Core<M>, guid: &str, (version, interface): Origin) -> Vec<u8> {
    let mut p = Vec::new();
    p.push(version as u8);
    p.push(interface as u8);
    p.push(mode_code(core.mode));
    for x in [core.time, core.start_time, core.last_successful_time] {
        put_f64(&mut p, x);
    }
    put_u64(&mut p, core.activations);
    for opt in [core.stop_time, core.tolerance] {
        p.push(opt.is_some() as u8);
        put_f64(&mut p, opt.unwrap_or(0.0));
    }
    p.push(core.outputs_current as u8);
    put_u64(&mut p, core.values.all().len() as u64);
    for v in core.values.all() {
        match v {
            Value::Real(x) => {
                p.push(0);
                put_f64(&mut p, *x)
            }
            Value::Integer(i) => {
                p.push(1);
                p.extend_from_slice(&i.to_le_bytes())
            }
            Value::Boolean(b) => {
                p.push(2);
                p.push(*b as u8)
            }
            Value::String(s) => {
                p.push(3);
                put_u64(&mut p, s.len() as u64);
                p.extend_from_slice(s.as_bytes())
            }
            Value::Clock(active) => {
                p.push(4);
                p.push(*active as u8)
            }
        }
    }
    core.input_derivatives.iter().for_each(|&d| put_f64(&mut p, d));
    match &core.model {
        None => p.push(0),
        Some(m) => {
            p.push(1);
            let s = m.save();
            put_u64(&mut p, s.len() as u64);
            s.iter().for_each(|&x| put_f64(&mut p, x));
        }
    }
    let mut out = Vec::with_capacity(p.len() + 64);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(guid.len() as u32).to_le_bytes());
    out.extend_from_slice(guid.as_bytes());
    put_u64(&mut out, p.len() as u64);
    out.extend_from_slice(&p);
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}

/// The length of the header of a state of the FMU with `guid`: magic, format version, GUID,
/// payload length.
pub fn head_len(guid: &str) -> usize {
    MAGIC.len() + 4 + 4 + guid.len() + 8
}

/// The whole length a header announces (header, payload, checksum), if the bytes begin with
/// a header of this format; what follows is not read.
pub fn announced_len(head: &[u8]) -> Option<usize> {
    let at = |from: usize, n: usize| head.get(from..from + n);
    if at(0, MAGIC.len())? != MAGIC {
        return None;
    }
    let guid_len = u32::from_le_bytes(at(MAGIC.len() + 4, 4)?.try_into().ok()?) as usize;
    let payload_at = MAGIC.len() + 8 + guid_len;
    let payload = u64::from_le_bytes(at(payload_at, 8)?.try_into().ok()?) as usize;
    (payload_at + 8).checked_add(payload)?.checked_add(4)
}

/// Parses bytes written by [`serialize`] for this model and GUID, by an instance of `origin`.
pub fn deserialize<M: Model>(bytes: &[u8], guid: &str, origin: Origin) -> Result<Core<M>, String> {
    if bytes.len() < MAGIC.len() + 4 + 4 + 8 + 4 {
        return Err(format!("{} bytes are too few for a serialised FMU state", bytes.len()));
    }
    let (body, crc) = bytes.split_at(bytes.len() - 4);
    let crc = u32::from_le_bytes(crc.try_into().unwrap_or_default());
    if !body.starts_with(MAGIC) {
        return Err("the bytes are not a boomsim FMU state (wrong magic)".into());
    }
    if crc32fast::hash(body) != crc {
        return Err("the serialised FMU state is corrupted (checksum mismatch)".into());
    }
    let mut r = Reader { b: body, at: MAGIC.len() };
    let version = u32::from_le_bytes(r.take(4)?.try_into().unwrap_or_default());
    if version != FORMAT_VERSION {
        return Err(format!("serialised format version {version}; this FMU reads version {FORMAT_VERSION}"));
    }
    let n = u32::from_le_bytes(r.take(4)?.try_into().unwrap_or_default()) as usize;
    let their_guid = String::from_utf8_lossy(r.take(n)?).into_owned();
    if their_guid != guid {
        return Err(format!("the state belongs to the FMU with GUID {their_guid}, not to {guid}"));
    }
    let len = r.u64()? as usize;
    if len != body.len() - r.at {
        return Err(format!("payload length {len} does not match the {} bytes present", body.len() - r.at));
    }
    let taken = decode_origin(r.take(1)?[0], r.take(1)?[0])?;
    if taken != origin {
        return Err(format!(
            "the state was taken by {}, and this instance is {}",
            origin_name(taken),
            origin_name(origin)
        ));
    }
    let state = decode_mode(r.take(1)?[0])?;
    if !can_save(state, origin) {
        return Err(format!("state {state:?}, which {} never saves", origin_name(origin)));
    }
    let (time, start_time, last_successful_time) = (r.f64()?, r.f64()?, r.f64()?);
    let activations = r.u64()?;
    if activation::<M>(start_time, activations).is_some_and(|(t, _)| !t.is_finite()) {
        return Err(format!("the serialised FMU state counts {activations} activations of the Clock"));
    }
    let mut opt = || -> Result<Option<f64>, String> {
        let some = r.take(1)?[0] != 0;
        let x = r.f64()?;
        Ok(some.then_some(x))
    };
    let (stop_time, tolerance) = (opt()?, opt()?);
    // Computed values are not trusted: they are computed anew before a get (see below).
    let _outputs_current = r.take(1)?[0] != 0;
    let mut values = Values::new(M::VARIABLES);
    let count = r.u64()? as usize;
    if count != M::VARIABLES.len() {
        return Err(format!("the state has {count} variables; {} has {}", M::INFO.identifier, M::VARIABLES.len()));
    }
    for i in 0..count {
        let v = match (r.take(1)?[0], values.at(i)) {
            (0, Value::Real(_)) => Value::Real(r.f64()?),
            (1, Value::Integer(_)) => Value::Integer(i32::from_le_bytes(r.take(4)?.try_into().unwrap_or_default())),
            (2, Value::Boolean(_)) => Value::Boolean(r.take(1)?[0] != 0),
            (4, Value::Clock(_)) => Value::Clock(r.take(1)?[0] != 0),
            (3, Value::String(_)) => {
                let n = r.u64()? as usize;
                Value::String(String::from_utf8(r.take(n)?.to_vec()).map_err(|e| e.to_string())?)
            }
            (tag, _) => {
                return Err(format!(
                    "value {i} has type tag {tag}, which does not match variable \"{}\"",
                    M::VARIABLES[i].name
                ))
            }
        };
        values.put(i, v);
    }
    // What the importer sets (parameters, inputs) is checked as fmi2SetReal checks it; what the
    // model computed (outputs, locals, der()) is whatever it was, a non-finite value too (a
    // model outside its valid range, a derivative Model Exchange answered with fmi2Discard), and
    // is computed anew from the restored model before the next get (`outputs_current` false), so
    // a forged one is never read.
    let settable = |v: &Variable| matches!(v.causality, Causality::Parameter | Causality::Input);
    for (v, x) in M::VARIABLES.iter().zip(values.all()).filter(|(v, _)| settable(v)) {
        in_range(v, x).map_err(|e| format!("the serialised FMU state holds {e}"))?;
    }
    check_times(time, start_time, last_successful_time, stop_time, tolerance)?;
    let input_derivatives = (0..count).map(|_| r.f64()).collect::<Result<Vec<_>, _>>()?;
    if let Some(i) = input_derivatives.iter().position(|d| !d.is_finite()) {
        return Err(format!("the serialised FMU state holds a non-finite derivative of \"{}\"", M::VARIABLES[i].name));
    }
    let broken = matches!(state, Mode::Error | Mode::Terminated | Mode::StepFailed);
    let model = match r.take(1)?[0] {
        0 => None,
        _ => {
            let n = r.u64()? as usize;
            let s = (0..n).map(|_| r.f64()).collect::<Result<Vec<_>, _>>()?;
            // A model a failed step or an error broke may not load (its solver stopped at NaN):
            // the state reads back without it, in StepFailed, Error or Terminated, where no step
            // follows (only gets, terminate, reset and restore).
            match Driven::<M>::load(&values, &s) {
                Err(_) if broken => None,
                loaded => Some(loaded?),
            }
        }
    };
    if r.at != body.len() {
        return Err(format!("{} unexpected bytes after the state", body.len() - r.at));
    }
    // A model exists exactly once initialisation has ended; Error and Terminated may come before
    // it (a panic, FMI 3.0: any fmi3Error), and a broken one may not load (above).
    let initialised = !matches!(state, Mode::Instantiated | Mode::InitializationMode);
    if model.is_some() != initialised && !broken {
        return Err(format!("state {state:?} {} a model", if initialised { "needs" } else { "cannot have" }));
    }
    Ok(Core {
        mode: state,
        values,
        input_derivatives,
        model: model.map(Box::new),
        time,
        start_time,
        stop_time,
        tolerance,
        last_successful_time,
        activations,
        outputs_current: false,
        derivatives_current: false,
    })
}

/// The instance clock and experiment of a restored state: what fmi2SetupExperiment would accept
/// and the clocks at or after the start (Model Exchange may set the time back before the last
/// completed integrator step: fmi2SetTime).
fn check_times(time: f64, start: f64, last: f64, stop: Option<f64>, tolerance: Option<f64>) -> Result<(), String> {
    let (lo, hi) = TOLERANCE_RANGE;
    let ok = [time, start, last].iter().all(|t| t.is_finite())
        && time >= start
        && last >= start
        && stop.is_none_or(|s| s.is_finite() && s >= start)
        && tolerance.is_none_or(|t| (lo..=hi).contains(&t));
    if ok {
        return Ok(());
    }
    Err(format!(
        "the serialised FMU state has inconsistent times or tolerance: time {}, start {}, last successful {}, stop {}, tolerance {}",
        num(time),
        num(start),
        num(last),
        stop.map_or("none".into(), num),
        tolerance.map_or("none".into(), num)
    ))
}

fn put_f64(out: &mut Vec<u8>, x: f64) {
    out.extend_from_slice(&x.to_le_bytes());
}
fn put_u64(out: &mut Vec<u8>, x: u64) {
    out.extend_from_slice(&x.to_le_bytes());
}

/// Whether an instance of `origin` can take an FMU state in `state`: never inside doStep's
/// Intermediate Update Mode (FMI 3.0, 4.2.3: the FMU state functions are not among its calls;
/// FMI 2.0 has no such mode), never in StepCanceled (no step is asynchronous), and only in the
/// states of its interface (Event Mode: both).
fn can_save(state: Mode, (_, interface): Origin) -> bool {
    !matches!(state, Mode::IntermediateUpdate | Mode::StepCanceled)
        && state.interface().is_none_or(|i| i == interface)
}

/// An instance's FMI version and interface for people.
fn origin_name((version, interface): Origin) -> String {
    let v = if version == Version::Fmi2 { "2.0" } else { "3.0" };
    format!("an FMI {v} {interface:?} instance")
}

fn decode_origin(version: u8, interface: u8) -> Result<Origin, String> {
    let version = match version {
        0 => Version::Fmi2,
        1 => Version::Fmi3,
        _ => return Err(format!("invalid FMI version code {version}")),
    };
    let interface = match interface {
        0 => Interface::ModelExchange,
        1 => Interface::CoSimulation,
        _ => return Err(format!("invalid interface code {interface}")),
    };
    Ok((version, interface))
}

fn mode_code(s: Mode) -> u8 {
    Mode::ALL.iter().position(|&x| x == s).unwrap_or(0) as u8
}
fn decode_mode(c: u8) -> Result<Mode, String> {
    Mode::ALL.get(c as usize).copied().ok_or_else(|| format!("invalid state code {c}"))
}

/// A bounds-checked cursor.
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end =
            self.at.checked_add(n).filter(|&e| e <= self.b.len()).ok_or("the serialised FMU state is truncated")?;
        let s = &self.b[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.take(8)?.try_into().unwrap_or_default()))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap_or_default()))
    }
}
