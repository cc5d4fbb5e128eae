//! The FMI 3.0 C API (`fmi3Functions.h`), written from the standard's function types.
//!
//! Every function the standard requires a shared library to export is here. The
//! co-simulation functions work; the Model Exchange and Scheduled Execution entry points,
//! clocks, directional/adjoint derivatives and the other variable types return `fmi3Error`
//! (or a null instance) and log why.
//!
//! Every exported function runs its body under `catch_unwind`: a panic becomes `fmi3Error`
//! with a log message and the instance enters the error state; nothing unwinds into C.
//!
//! # Safety
//! These functions are called by an FMI importer, which must keep to the FMI 3.0 calling
//! contract: `instance` is a pointer returned by `fmi3InstantiateCoSimulation` and not yet
//! freed, arrays hold the number of elements passed with them, out-pointers are valid.
//! Null pointers and length mismatches are detected and reported as `fmi3Error`.

#![allow(non_snake_case, clippy::missing_safety_doc, clippy::too_many_arguments)]

use std::ffi::{CStr, c_char, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

use crate::instance::{FmuState, Instance, LogCallback, Logger, Mode};
use crate::variables::{INSTANTIATION_TOKEN, Kind, LOG_CATEGORIES, MODEL_IDENTIFIER};

/// `fmi3Status`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// fmi3OK
    Ok = 0,
    /// fmi3Warning
    Warning = 1,
    /// fmi3Discard
    Discard = 2,
    /// fmi3Error
    Error = 3,
    /// fmi3Fatal
    Fatal = 4,
}

/// `fmi3Instance`.
pub type Fmi3Instance = *mut c_void;
/// `fmi3InstanceEnvironment`.
pub type Fmi3InstanceEnvironment = *mut c_void;
/// `fmi3FMUState`.
pub type Fmi3FmuState = *mut c_void;
/// `fmi3ValueReference`.
pub type ValueReference = u32;
/// `fmi3String`.
pub type Fmi3String = *const c_char;
/// `fmi3Binary`.
pub type Fmi3Binary = *const u8;
/// `fmi3IntermediateUpdateCallback`.
pub type IntermediateUpdateCallback = Option<
    unsafe extern "C" fn(
        env: Fmi3InstanceEnvironment,
        intermediate_update_time: f64,
        intermediate_variable_set_requested: bool,
        intermediate_variable_get_allowed: bool,
        intermediate_step_finished: bool,
        can_return_early: bool,
        early_return_requested: *mut bool,
        early_return_time: *mut f64,
    ),
>;
/// `fmi3ClockUpdateCallback`.
pub type ClockUpdateCallback = Option<unsafe extern "C" fn(env: Fmi3InstanceEnvironment)>;
/// `fmi3LockPreemptionCallback` / `fmi3UnlockPreemptionCallback`.
pub type PreemptionCallback = Option<unsafe extern "C" fn()>;

/// Category indices into [`LOG_CATEGORIES`].
const LOG_ERROR: usize = 0;
const LOG_CALLS: usize = 2;

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<String>().cloned().or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string())).unwrap_or_default()
}

/// Run `body` on the instance behind `ptr`: errors and panics are logged, put the instance
/// in the error state and return `fmi3Error`. `allow_in_error` lists calls allowed there.
pub(crate) fn with_instance(
    ptr: Fmi3Instance,
    call: &str,
    allow_in_error: bool,
    body: impl FnOnce(&mut Instance) -> Result<(), String>,
) -> Status {
    if ptr.is_null() {
        return Status::Error;
    }
    // SAFETY: a non-null instance pointer comes from fmi3InstantiateCoSimulation (contract).
    let inst = unsafe { &mut *(ptr as *mut Instance) };
    let result = catch_unwind(AssertUnwindSafe(|| {
        inst.logger.log(Status::Ok, LOG_CALLS, call);
        if inst.mode() == Mode::Error && !allow_in_error {
            return Err(format!("{call} is not allowed in the error state (use fmi3SetFMUState or fmi3Reset)"));
        }
        body(inst)
    }));
    let msg = match result {
        Ok(Ok(())) => return Status::Ok,
        Ok(Err(e)) => e,
        Err(p) => format!("internal error (please report): {}", panic_message(p.as_ref())),
    };
    // the logger is plain data: usable even if the body panicked half-way
    let _ = catch_unwind(AssertUnwindSafe(|| {
        inst.fail();
        inst.logger.log(Status::Error, LOG_ERROR, &format!("{}: {call}: {msg}", inst.name));
    }));
    Status::Error
}

/// A slice from a C array; empty for n = 0 (any pointer), an error for a null pointer.
unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> Result<&'a [T], String> {
    if n == 0 {
        Ok(&[])
    } else if p.is_null() {
        Err(format!("{what} is null"))
    } else {
        // SAFETY: the importer passes n elements at p (contract).
        Ok(unsafe { std::slice::from_raw_parts(p, n) })
    }
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, what: &str) -> Result<&'a mut [T], String> {
    if n == 0 {
        Ok(&mut [])
    } else if p.is_null() {
        Err(format!("{what} is null"))
    } else {
        // SAFETY: as for `slice`.
        Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
    }
}

fn check_counts(n_vr: usize, n_values: usize) -> Result<(), String> {
    if n_vr == n_values {
        Ok(())
    } else {
        Err(format!("nValues = {n_values} differs from nValueReferences = {n_vr} (all variables are scalars)"))
    }
}

unsafe fn cstr(p: Fmi3String) -> String {
    if p.is_null() {
        String::new()
    } else {
        // SAFETY: the importer passes a NUL-terminated string (contract).
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }
}

/// Log through a bare callback (no instance yet).
fn log_bare(callback: Option<LogCallback>, env: Fmi3InstanceEnvironment, message: &str) {
    let logger = Logger { callback, env, enabled: [false; 3] };
    logger.log(Status::Error, LOG_ERROR, message);
}

// ---------------------------------------------------------------------------------------
// Inquire version, logging

/// `fmi3GetVersion`: "3.0".
#[unsafe(no_mangle)]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

/// `fmi3SetDebugLogging`: categories from `modelDescription.xml`; none given = all.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: Fmi3Instance,
    logging_on: bool,
    n_categories: usize,
    categories: *const Fmi3String,
) -> Status {
    with_instance(instance, "fmi3SetDebugLogging", true, |inst| {
        // SAFETY: contract.
        let cats = unsafe { slice(categories, n_categories, "categories")? };
        if cats.is_empty() {
            inst.logger.enabled = [logging_on; 3];
            return Ok(());
        }
        for &c in cats {
            // SAFETY: contract.
            let name = unsafe { cstr(c) };
            let k = LOG_CATEGORIES
                .iter()
                .position(|(n, _)| *n == name)
                .ok_or_else(|| format!("unknown log category `{name}`"))?;
            inst.logger.enabled[k] = logging_on;
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Instantiation

/// `fmi3InstantiateModelExchange`: not supported (co-simulation only); returns null.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    instance_name: Fmi3String,
    _instantiation_token: Fmi3String,
    _resource_path: Fmi3String,
    _visible: bool,
    _logging_on: bool,
    instance_environment: Fmi3InstanceEnvironment,
    log_message: Option<LogCallback>,
) -> Fmi3Instance {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: contract.
        let name = unsafe { cstr(instance_name) };
        log_bare(log_message, instance_environment, &format!("{name}: {MODEL_IDENTIFIER} supports co-simulation only"));
    }));
    std::ptr::null_mut()
}

/// `fmi3InstantiateCoSimulation`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instance_name: Fmi3String,
    instantiation_token: Fmi3String,
    _resource_path: Fmi3String,
    _visible: bool,
    logging_on: bool,
    event_mode_used: bool,
    early_return_allowed: bool,
    _required_intermediate_variables: *const ValueReference,
    n_required_intermediate_variables: usize,
    instance_environment: Fmi3InstanceEnvironment,
    log_message: Option<LogCallback>,
    _intermediate_update: IntermediateUpdateCallback,
) -> Fmi3Instance {
    let made = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: contract.
        let name = unsafe { cstr(instance_name) };
        // SAFETY: contract.
        let token = unsafe { cstr(instantiation_token) };
        if !instantiation_token.is_null() && token != INSTANTIATION_TOKEN {
            log_bare(
                log_message,
                instance_environment,
                &format!("{name}: instantiationToken `{token}` does not match this binary ({INSTANTIATION_TOKEN})"),
            );
            return std::ptr::null_mut();
        }
        if n_required_intermediate_variables > 0 {
            log_bare(log_message, instance_environment, &format!("{name}: intermediate variables are not provided"));
            return std::ptr::null_mut();
        }
        let logger = Logger { callback: log_message, env: instance_environment, enabled: [logging_on; 3] };
        let inst = Box::new(Instance::new(name, logger, event_mode_used));
        if early_return_allowed {
            inst.logger.log(Status::Ok, LOG_CALLS, "early return is never used");
        }
        Box::into_raw(inst) as Fmi3Instance
    }));
    made.unwrap_or(std::ptr::null_mut())
}

/// `fmi3InstantiateScheduledExecution`: not supported; returns null.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    instance_name: Fmi3String,
    _instantiation_token: Fmi3String,
    _resource_path: Fmi3String,
    _visible: bool,
    _logging_on: bool,
    instance_environment: Fmi3InstanceEnvironment,
    log_message: Option<LogCallback>,
    _clock_update: ClockUpdateCallback,
    _lock_preemption: PreemptionCallback,
    _unlock_preemption: PreemptionCallback,
) -> Fmi3Instance {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: contract.
        let name = unsafe { cstr(instance_name) };
        log_bare(log_message, instance_environment, &format!("{name}: {MODEL_IDENTIFIER} supports co-simulation only"));
    }));
    std::ptr::null_mut()
}

/// `fmi3FreeInstance`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeInstance(instance: Fmi3Instance) {
    if instance.is_null() {
        return;
    }
    let _ = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: the pointer came from Box::into_raw in fmi3InstantiateCoSimulation.
        drop(unsafe { Box::from_raw(instance as *mut Instance) });
    }));
}

// ---------------------------------------------------------------------------------------
// Modes

/// `fmi3EnterInitializationMode` (tolerance ignored: the model has its own step control).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: Fmi3Instance,
    _tolerance_defined: bool,
    _tolerance: f64,
    start_time: f64,
    stop_time_defined: bool,
    stop_time: f64,
) -> Status {
    with_instance(instance, "fmi3EnterInitializationMode", false, |inst| {
        inst.enter_initialization(start_time, stop_time_defined.then_some(stop_time))
    })
}

/// `fmi3ExitInitializationMode`: validates the parameters and builds the model.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: Fmi3Instance) -> Status {
    with_instance(instance, "fmi3ExitInitializationMode", false, |inst| inst.exit_initialization())
}

/// `fmi3EnterEventMode` (only with eventModeUsed; there are no events).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterEventMode(instance: Fmi3Instance) -> Status {
    with_instance(instance, "fmi3EnterEventMode", false, |inst| inst.enter_event_mode())
}

/// `fmi3Terminate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Terminate(instance: Fmi3Instance) -> Status {
    with_instance(instance, "fmi3Terminate", false, |inst| inst.terminate())
}

/// `fmi3Reset`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Reset(instance: Fmi3Instance) -> Status {
    with_instance(instance, "fmi3Reset", true, |inst| {
        inst.reset();
        Ok(())
    })
}

/// `fmi3EnterStepMode` (from event mode).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterStepMode(instance: Fmi3Instance) -> Status {
    with_instance(instance, "fmi3EnterStepMode", false, |inst| inst.enter_step_mode())
}

/// `fmi3DoStep`: advances the model from `currentCommunicationPoint` by
/// `communicationStepSize` with the inputs held constant (zero-order hold).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DoStep(
    instance: Fmi3Instance,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_fmu_state_prior_to_current_point: bool,
    event_handling_needed: *mut bool,
    terminate_simulation: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> Status {
    with_instance(instance, "fmi3DoStep", false, |inst| {
        let flags = [event_handling_needed, terminate_simulation, early_return];
        if flags.iter().any(|p| p.is_null()) || last_successful_time.is_null() {
            return Err("an output argument is null".into());
        }
        // SAFETY: checked non-null; the importer owns them (contract).
        unsafe {
            for p in flags {
                *p = false;
            }
            *last_successful_time = current_communication_point;
        }
        let t = inst.do_step(current_communication_point, communication_step_size)?;
        // SAFETY: as above.
        unsafe { *last_successful_time = t };
        Ok(())
    })
}

/// `fmi3UpdateDiscreteStates` (event mode): nothing to update, no next event.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
    instance: Fmi3Instance,
    discrete_states_need_update: *mut bool,
    terminate_simulation: *mut bool,
    nominals_of_continuous_states_changed: *mut bool,
    values_of_continuous_states_changed: *mut bool,
    next_event_time_defined: *mut bool,
    next_event_time: *mut f64,
) -> Status {
    with_instance(instance, "fmi3UpdateDiscreteStates", false, |inst| {
        inst.update_discrete_states()?;
        let flags = [
            discrete_states_need_update,
            terminate_simulation,
            nominals_of_continuous_states_changed,
            values_of_continuous_states_changed,
            next_event_time_defined,
        ];
        if flags.iter().any(|p| p.is_null()) || next_event_time.is_null() {
            return Err("an output argument is null".into());
        }
        // SAFETY: checked non-null (contract).
        unsafe {
            for p in flags {
                *p = false;
            }
            *next_event_time = 0.0;
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Getters and setters

unsafe fn get_values<T>(
    instance: Fmi3Instance,
    call: &str,
    kind: Kind,
    vrs: *const ValueReference,
    n_vr: usize,
    values: *mut T,
    n_values: usize,
    convert: impl Fn(f64) -> T,
) -> Status {
    with_instance(instance, call, true, |inst| {
        check_counts(n_vr, n_values)?;
        // SAFETY: contract.
        let (vrs, out) = unsafe { (slice(vrs, n_vr, "valueReferences")?, slice_mut(values, n_values, "values")?) };
        for (vr, o) in vrs.iter().zip(out.iter_mut()) {
            *o = convert(inst.get(*vr, kind)?);
        }
        Ok(())
    })
}

unsafe fn set_values<T: Copy>(
    instance: Fmi3Instance,
    call: &str,
    kind: Kind,
    vrs: *const ValueReference,
    n_vr: usize,
    values: *const T,
    n_values: usize,
    convert: impl Fn(T) -> f64,
) -> Status {
    with_instance(instance, call, false, |inst| {
        check_counts(n_vr, n_values)?;
        // SAFETY: contract.
        let (vrs, vals) = unsafe { (slice(vrs, n_vr, "valueReferences")?, slice(values, n_values, "values")?) };
        for (vr, v) in vrs.iter().zip(vals) {
            inst.set(*vr, kind, convert(*v))?;
        }
        Ok(())
    })
}

/// `fmi3GetFloat64`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: Fmi3Instance,
    value_references: *const ValueReference,
    n_value_references: usize,
    values: *mut f64,
    n_values: usize,
) -> Status {
    // SAFETY: forwarded contract.
    unsafe {
        get_values(
            instance,
            "fmi3GetFloat64",
            Kind::Float64,
            value_references,
            n_value_references,
            values,
            n_values,
            |x| x,
        )
    }
}

/// `fmi3SetFloat64`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: Fmi3Instance,
    value_references: *const ValueReference,
    n_value_references: usize,
    values: *const f64,
    n_values: usize,
) -> Status {
    // SAFETY: forwarded contract.
    unsafe {
        set_values(
            instance,
            "fmi3SetFloat64",
            Kind::Float64,
            value_references,
            n_value_references,
            values,
            n_values,
            |x| x,
        )
    }
}

/// `fmi3GetInt32` (the model selector and the element counts).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetInt32(
    instance: Fmi3Instance,
    value_references: *const ValueReference,
    n_value_references: usize,
    values: *mut i32,
    n_values: usize,
) -> Status {
    // SAFETY: forwarded contract.
    unsafe {
        get_values(instance, "fmi3GetInt32", Kind::Int32, value_references, n_value_references, values, n_values, |x| {
            x as i32
        })
    }
}

/// `fmi3SetInt32`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetInt32(
    instance: Fmi3Instance,
    value_references: *const ValueReference,
    n_value_references: usize,
    values: *const i32,
    n_values: usize,
) -> Status {
    // SAFETY: forwarded contract.
    unsafe {
        set_values(instance, "fmi3SetInt32", Kind::Int32, value_references, n_value_references, values, n_values, |x| {
            f64::from(x)
        })
    }
}

/// Getters and setters of types this FMU has no variables of: an empty call is OK, any
/// value reference is an error naming the call.
macro_rules! no_variables_of_type {
    ($get:ident, $set:ident, $t:ty) => {
        #[doc = concat!("`", stringify!($get), "`: this FMU has no variables of this type.")]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $get(
            instance: Fmi3Instance,
            _value_references: *const ValueReference,
            n_value_references: usize,
            _values: *mut $t,
            _n_values: usize,
        ) -> Status {
            no_such_variables(instance, stringify!($get), n_value_references)
        }

        #[doc = concat!("`", stringify!($set), "`: this FMU has no variables of this type.")]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $set(
            instance: Fmi3Instance,
            _value_references: *const ValueReference,
            n_value_references: usize,
            _values: *const $t,
            _n_values: usize,
        ) -> Status {
            no_such_variables(instance, stringify!($set), n_value_references)
        }
    };
}

fn no_such_variables(instance: Fmi3Instance, call: &str, n: usize) -> Status {
    with_instance(instance, call, true, |_| {
        if n == 0 { Ok(()) } else { Err(format!("{MODEL_IDENTIFIER} has no variables of this type")) }
    })
}

no_variables_of_type!(fmi3GetFloat32, fmi3SetFloat32, f32);
no_variables_of_type!(fmi3GetInt8, fmi3SetInt8, i8);
no_variables_of_type!(fmi3GetUInt8, fmi3SetUInt8, u8);
no_variables_of_type!(fmi3GetInt16, fmi3SetInt16, i16);
no_variables_of_type!(fmi3GetUInt16, fmi3SetUInt16, u16);
no_variables_of_type!(fmi3GetUInt32, fmi3SetUInt32, u32);
no_variables_of_type!(fmi3GetInt64, fmi3SetInt64, i64);
no_variables_of_type!(fmi3GetUInt64, fmi3SetUInt64, u64);
no_variables_of_type!(fmi3GetBoolean, fmi3SetBoolean, bool);
no_variables_of_type!(fmi3GetString, fmi3SetString, Fmi3String);

/// `fmi3GetBinary`: no binary variables.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetBinary(
    instance: Fmi3Instance,
    _value_references: *const ValueReference,
    n_value_references: usize,
    _value_sizes: *mut usize,
    _values: *mut Fmi3Binary,
    _n_values: usize,
) -> Status {
    no_such_variables(instance, "fmi3GetBinary", n_value_references)
}

/// `fmi3SetBinary`: no binary variables.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetBinary(
    instance: Fmi3Instance,
    _value_references: *const ValueReference,
    n_value_references: usize,
    _value_sizes: *const usize,
    _values: *const Fmi3Binary,
    _n_values: usize,
) -> Status {
    no_such_variables(instance, "fmi3SetBinary", n_value_references)
}

/// `fmi3GetClock`: no clocks.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetClock(
    instance: Fmi3Instance,
    _value_references: *const ValueReference,
    n_value_references: usize,
    _values: *mut bool,
) -> Status {
    no_such_variables(instance, "fmi3GetClock", n_value_references)
}

/// `fmi3SetClock`: no clocks.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetClock(
    instance: Fmi3Instance,
    _value_references: *const ValueReference,
    n_value_references: usize,
    _values: *const bool,
) -> Status {
    no_such_variables(instance, "fmi3SetClock", n_value_references)
}

// ---------------------------------------------------------------------------------------
// FMU state

/// `fmi3GetFMUState`: a new state, or `*FMUState` overwritten when it is not null.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFMUState(instance: Fmi3Instance, fmu_state: *mut Fmi3FmuState) -> Status {
    with_instance(instance, "fmi3GetFMUState", false, |inst| {
        if fmu_state.is_null() {
            return Err("FMUState is null".into());
        }
        let s = inst.get_state()?;
        // SAFETY: checked non-null; a non-null *fmu_state is a state from this library.
        unsafe {
            let existing = *fmu_state as *mut FmuState;
            if existing.is_null() {
                *fmu_state = Box::into_raw(Box::new(s)) as Fmi3FmuState;
            } else {
                *existing = s;
            }
        }
        Ok(())
    })
}

/// `fmi3SetFMUState`: rollback; allowed in the error state.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFMUState(instance: Fmi3Instance, fmu_state: Fmi3FmuState) -> Status {
    with_instance(instance, "fmi3SetFMUState", true, |inst| {
        if fmu_state.is_null() {
            return Err("FMUState is null".into());
        }
        // SAFETY: a state made by fmi3GetFMUState / fmi3DeserializeFMUState (contract).
        let s = unsafe { &*(fmu_state as *const FmuState) };
        inst.set_state(s)
    })
}

/// `fmi3FreeFMUState`: frees `*FMUState` and sets it to null.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeFMUState(instance: Fmi3Instance, fmu_state: *mut Fmi3FmuState) -> Status {
    with_instance(instance, "fmi3FreeFMUState", true, |_| {
        if fmu_state.is_null() {
            return Ok(());
        }
        // SAFETY: checked non-null; *fmu_state came from Box::into_raw here (contract).
        unsafe {
            let p = *fmu_state as *mut FmuState;
            if !p.is_null() {
                drop(Box::from_raw(p));
            }
            *fmu_state = std::ptr::null_mut();
        }
        Ok(())
    })
}

/// `fmi3SerializedFMUStateSize`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: Fmi3Instance,
    fmu_state: Fmi3FmuState,
    size: *mut usize,
) -> Status {
    with_instance(instance, "fmi3SerializedFMUStateSize", true, |_| {
        if fmu_state.is_null() || size.is_null() {
            return Err("FMUState or size is null".into());
        }
        // SAFETY: contract, checked non-null.
        unsafe { *size = (*(fmu_state as *const FmuState)).to_bytes().len() };
        Ok(())
    })
}

/// `fmi3SerializeFMUState`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: Fmi3Instance,
    fmu_state: Fmi3FmuState,
    serialized_state: *mut u8,
    size: usize,
) -> Status {
    with_instance(instance, "fmi3SerializeFMUState", true, |_| {
        if fmu_state.is_null() {
            return Err("FMUState is null".into());
        }
        // SAFETY: contract, checked non-null.
        let bytes = unsafe { &*(fmu_state as *const FmuState) }.to_bytes();
        if size != bytes.len() {
            return Err(format!("size = {size}, the serialized state has {} bytes", bytes.len()));
        }
        // SAFETY: the importer passes `size` writable bytes (contract).
        unsafe { slice_mut(serialized_state, size, "serializedState")? }.copy_from_slice(&bytes);
        Ok(())
    })
}

/// `fmi3DeserializeFMUState`: a new state (`*FMUState` must be freed by fmi3FreeFMUState).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: Fmi3Instance,
    serialized_state: *const u8,
    size: usize,
    fmu_state: *mut Fmi3FmuState,
) -> Status {
    with_instance(instance, "fmi3DeserializeFMUState", true, |_| {
        if fmu_state.is_null() {
            return Err("FMUState is null".into());
        }
        // SAFETY: contract.
        let s = FmuState::from_bytes(unsafe { slice(serialized_state, size, "serializedState")? })?;
        // SAFETY: checked non-null.
        unsafe {
            let existing = *fmu_state as *mut FmuState;
            if existing.is_null() {
                *fmu_state = Box::into_raw(Box::new(s)) as Fmi3FmuState;
            } else {
                *existing = s;
            }
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Unsupported functions: fmi3Error with a message

fn unsupported(instance: Fmi3Instance, call: &str) -> Status {
    with_instance(instance, call, true, |_| Err(format!("not supported by {MODEL_IDENTIFIER}")))
}

/// Defines exported functions that only report `fmi3Error` ("not supported").
macro_rules! unsupported_fns {
    ($( $name:ident ( $( $arg:ident : $t:ty ),* ) );* $(;)?) => {
        $(
            #[doc = concat!("`", stringify!($name), "`: not supported (fmi3Error).")]
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn $name(instance: Fmi3Instance $(, $arg: $t)*) -> Status {
                $( let _ = $arg; )*
                unsupported(instance, stringify!($name))
            }
        )*
    };
}

unsupported_fns! {
    fmi3GetNumberOfVariableDependencies(value_reference: ValueReference, n_dependencies: *mut usize);
    fmi3GetVariableDependencies(
        dependent: ValueReference,
        element_indices_of_dependent: *mut usize,
        independents: *mut ValueReference,
        element_indices_of_independents: *mut usize,
        dependency_kinds: *mut i32,
        n_dependencies: usize
    );
    fmi3GetDirectionalDerivative(
        unknowns: *const ValueReference,
        n_unknowns: usize,
        knowns: *const ValueReference,
        n_knowns: usize,
        seed: *const f64,
        n_seed: usize,
        sensitivity: *mut f64,
        n_sensitivity: usize
    );
    fmi3GetAdjointDerivative(
        unknowns: *const ValueReference,
        n_unknowns: usize,
        knowns: *const ValueReference,
        n_knowns: usize,
        seed: *const f64,
        n_seed: usize,
        sensitivity: *mut f64,
        n_sensitivity: usize
    );
    fmi3EnterConfigurationMode();
    fmi3ExitConfigurationMode();
    fmi3GetIntervalDecimal(
        value_references: *const ValueReference,
        n_value_references: usize,
        intervals: *mut f64,
        qualifiers: *mut i32
    );
    fmi3GetIntervalFraction(
        value_references: *const ValueReference,
        n_value_references: usize,
        counters: *mut u64,
        resolutions: *mut u64,
        qualifiers: *mut i32
    );
    fmi3GetShiftDecimal(value_references: *const ValueReference, n_value_references: usize, shifts: *mut f64);
    fmi3GetShiftFraction(
        value_references: *const ValueReference,
        n_value_references: usize,
        counters: *mut u64,
        resolutions: *mut u64
    );
    fmi3SetIntervalDecimal(value_references: *const ValueReference, n_value_references: usize, intervals: *const f64);
    fmi3SetIntervalFraction(
        value_references: *const ValueReference,
        n_value_references: usize,
        counters: *const u64,
        resolutions: *const u64
    );
    fmi3SetShiftDecimal(value_references: *const ValueReference, n_value_references: usize, shifts: *const f64);
    fmi3SetShiftFraction(
        value_references: *const ValueReference,
        n_value_references: usize,
        counters: *const u64,
        resolutions: *const u64
    );
    fmi3EvaluateDiscreteStates();
    fmi3EnterContinuousTimeMode();
    fmi3CompletedIntegratorStep(
        no_set_fmu_state_prior_to_current_point: bool,
        enter_event_mode: *mut bool,
        terminate_simulation: *mut bool
    );
    fmi3SetTime(time: f64);
    fmi3SetContinuousStates(continuous_states: *const f64, n_continuous_states: usize);
    fmi3GetContinuousStateDerivatives(derivatives: *mut f64, n_continuous_states: usize);
    fmi3GetEventIndicators(event_indicators: *mut f64, n_event_indicators: usize);
    fmi3GetContinuousStates(continuous_states: *mut f64, n_continuous_states: usize);
    fmi3GetNominalsOfContinuousStates(nominals: *mut f64, n_continuous_states: usize);
    fmi3GetNumberOfEventIndicators(n_event_indicators: *mut usize);
    fmi3GetNumberOfContinuousStates(n_continuous_states: *mut usize);
    fmi3GetOutputDerivatives(
        value_references: *const ValueReference,
        n_value_references: usize,
        orders: *const i32,
        values: *mut f64,
        n_values: usize
    );
    fmi3ActivateModelPartition(clock_reference: ValueReference, activation_time: f64);
}
