//! `ugl_bench._native`: the environments of `ugl-env` for Python (the package `ugl_bench`,
//! `python/ugl_bench/`, wraps it; `docs/python.md`).
//!
//! Every function checks its input and raises one `ValueError` naming what is wrong; nothing here
//! panics on a caller's input. Rollouts and pictures run without the GIL. The bytes are the
//! command line's: the same environments, built from the same `[env]` constants, the distractor
//! drawing from the seed's `distractor` stream episode after episode (`ugl rollout --seed`).

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;

use ugl_env::seed::{Component, Stream, stream};
use ugl_env::{EnvConfig, EnvKind, Environment, make_env};

/// The environment of this name, or a `ValueError` listing the names.
fn kind(name: &str) -> PyResult<EnvKind> {
    name.parse::<EnvKind>().map_err(PyValueError::new_err)
}

/// The `[env]` constants from a JSON object (the keys of a campaign file's `[env]` table), checked
/// as a campaign checks them; None: the defaults.
fn env_config(json: Option<&str>) -> PyResult<EnvConfig> {
    let cfg = match json {
        None => EnvConfig::default(),
        Some(text) => serde_json::from_str::<EnvConfig>(text)
            .map_err(|e| PyValueError::new_err(format!("config: {e}")))?,
    };
    cfg.validate()
        .map_err(|e| PyValueError::new_err(format!("config: {e}")))?;
    Ok(cfg)
}

/// The distractor's stream of a seed: the one `ugl rollout --seed` and a run draw from.
fn noise_stream(seed: u64) -> Stream {
    stream(seed, Component::Distractor)
}

/// Motor parameters that every environment accepts: `p` per episode, each finite.
fn check_params(values: &[f64], p: usize, what: &str) -> PyResult<()> {
    if let Some(i) = values.iter().position(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{what}: motor parameter {} of episode {} is {} (every parameter must be finite; \
             they are clipped to [-1, 1])",
            i % p,
            i / p,
            values[i]
        )));
    }
    Ok(())
}

/// The picture's shape as numpy sees it: (height, width) for gray pictures, (height, width,
/// channels) for colour ones.
fn picture_shape(kind: EnvKind) -> Vec<usize> {
    let s = kind.spec().image;
    if s.channels == 1 {
        vec![s.height, s.width]
    } else {
        vec![s.height, s.width, s.channels]
    }
}

/// The registered environments: a list of dicts (name, display name, description, motor
/// parameters, outcome size and names, objects and their outcome coordinates, picture shape,
/// whether it is one of the paper's).
#[pyfunction]
fn environments(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    for k in EnvKind::all() {
        let s = k.spec();
        let d = PyDict::new(py);
        d.set_item("name", s.name)?;
        d.set_item("display", s.display)?;
        d.set_item("description", s.description)?;
        d.set_item("params", s.params)?;
        d.set_item("state_dim", s.state_dim)?;
        d.set_item("outcome_columns", s.outcome_columns.to_vec())?;
        let objects = PyList::empty(py);
        for o in s.objects {
            objects.append((o.name, o.start, o.end, o.controllable))?;
        }
        d.set_item("objects", objects)?;
        d.set_item("image_shape", picture_shape(k))?;
        d.set_item("in_paper", s.in_paper)?;
        list.append(d)?;
    }
    Ok(list)
}

/// One environment with its distractor stream: the step-by-step view (one call, one episode).
#[pyclass(module = "ugl_bench._native", name = "Env")]
struct PyEnv {
    kind: EnvKind,
    env: Box<dyn Environment>,
    noise: Stream,
}

#[pymethods]
impl PyEnv {
    /// `Env(name, seed=0, config=None)`: `config` is a JSON object of `[env]` keys.
    #[new]
    #[pyo3(signature = (name, seed = 0, config = None))]
    fn new(name: &str, seed: u64, config: Option<&str>) -> PyResult<Self> {
        let kind = kind(name)?;
        let cfg = env_config(config)?;
        Ok(PyEnv {
            kind,
            env: make_env(kind, &cfg),
            noise: noise_stream(seed),
        })
    }

    /// Restart the distractor's stream from this seed's beginning.
    fn reseed(&mut self, seed: u64) {
        self.noise = noise_stream(seed);
    }

    #[getter]
    fn name(&self) -> &'static str {
        self.kind.name()
    }

    #[getter]
    fn params(&self) -> usize {
        self.env.param_dim()
    }

    #[getter]
    fn state_dim(&self) -> usize {
        self.env.state_dim()
    }

    #[getter]
    fn image_shape(&self) -> Vec<usize> {
        picture_shape(self.kind)
    }

    /// The objects' state before any episode (float64, `state_dim`).
    fn initial_state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.env.initial_state())
    }

    /// One episode: (outcome float64[state_dim], caught, hand (x, y)).
    fn rollout<'py>(
        &mut self,
        py: Python<'py>,
        params: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, bool, (f64, f64))> {
        let p = self.env.param_dim();
        let theta = params.to_vec().map_err(|_| {
            PyValueError::new_err("params: expected a contiguous float64 array".to_string())
        })?;
        if theta.len() != p {
            return Err(PyValueError::new_err(format!(
                "params: {} has {p} motor parameters per episode, got {}",
                self.kind,
                theta.len()
            )));
        }
        check_params(&theta, p, "params")?;
        let env = &self.env;
        let noise = &mut self.noise;
        let r = py.detach(move || env.rollout(&theta, noise));
        Ok((
            PyArray1::from_slice(py, r.outcome()),
            r.caught,
            (r.hand[0], r.hand[1]),
        ))
    }

    /// The picture of an outcome (float32, `image_shape`, values in [0, 1]).
    fn render<'py>(
        &self,
        py: Python<'py>,
        state: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let state = state.to_vec().map_err(|_| {
            PyValueError::new_err("state: expected a contiguous float64 array".to_string())
        })?;
        check_state(self.kind, &state, 1)?;
        let pictures = render_all(self.env.as_ref(), &state, 1, py);
        let arr = PyArray1::from_vec(py, pictures);
        Ok(arr.reshape(picture_shape(self.kind))?.into_any())
    }
}

/// Outcomes that every renderer accepts: `n` of `state_dim` finite values.
fn check_state(kind: EnvKind, values: &[f64], n: usize) -> PyResult<()> {
    let d = kind.state_dim();
    if values.len() != n * d {
        return Err(PyValueError::new_err(format!(
            "state: {kind}'s outcome has {d} values ({}), got {}",
            kind.spec().outcome_columns.join(", "),
            values.len() / n.max(1)
        )));
    }
    if let Some(i) = values.iter().position(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "state: value {} of outcome {} is {} (outcomes are finite, in [-1, 1])",
            i % d,
            i / d,
            values[i]
        )));
    }
    Ok(())
}

/// The pictures of `n` outcomes, in parallel, without the GIL.
fn render_all(env: &dyn Environment, states: &[f64], n: usize, py: Python<'_>) -> Vec<f32> {
    let len = env.image_len();
    let d = env.state_dim();
    py.detach(|| {
        let mut out = vec![0f32; n * len];
        out.par_chunks_mut(len)
            .zip(states.par_chunks(d))
            .for_each(|(pic, s)| env.render_into(s, pic));
        out
    })
}

/// `rollout(env, params, seed=0, images=False, config=None)`: `params` float64[N, P]; returns
/// the outcomes float64[N, state_dim], and with `images` also the pictures float32[N, ...].
/// Episode `i` is the `i`-th episode of `ugl rollout --env ENV --seed SEED` on the same
/// parameters: the distractor draws from the seed's stream episode after episode, so the
/// episodes run in order; the environments without a distractor, and the pictures, run on every
/// core (rayon; `RAYON_NUM_THREADS`). The GIL is released throughout.
#[pyfunction]
#[pyo3(signature = (env, params, seed = 0, images = false, config = None))]
fn rollout<'py>(
    py: Python<'py>,
    env: &str,
    params: PyReadonlyArray2<'py, f64>,
    seed: u64,
    images: bool,
    config: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let kind = kind(env)?;
    let cfg = env_config(config)?;
    let e = make_env(kind, &cfg);
    let p = e.param_dim();
    let shape = params.shape();
    if shape[1] != p {
        return Err(PyValueError::new_err(format!(
            "params: {kind} has {p} motor parameters per episode: expected shape (N, {p}), got \
             ({}, {})",
            shape[0], shape[1]
        )));
    }
    let n = shape[0];
    // A copy under the GIL: nothing can change the parameters while the episodes run.
    let theta: Vec<f64> = match params.as_slice() {
        Ok(s) => s.to_vec(),
        Err(_) => params.as_array().iter().copied().collect(),
    };
    check_params(&theta, p, "params")?;
    let d = e.state_dim();
    let env_ref = e.as_ref();
    let outcomes: Vec<f64> = py.detach(|| {
        let mut out = vec![0f64; n * d];
        if env_ref.draws_noise() {
            let mut noise = noise_stream(seed);
            for (o, t) in out.chunks_mut(d).zip(theta.chunks(p)) {
                o.copy_from_slice(env_ref.rollout(t, &mut noise).outcome());
            }
        } else {
            out.par_chunks_mut(d)
                .zip(theta.par_chunks(p))
                .for_each(|(o, t)| {
                    let mut noise = noise_stream(seed);
                    o.copy_from_slice(env_ref.rollout(t, &mut noise).outcome());
                });
        }
        out
    });
    let out = PyArray1::from_vec(py, outcomes.clone()).reshape([n, d])?;
    if !images {
        return Ok(out.into_any());
    }
    let pictures = render_all(env_ref, &outcomes, n, py);
    let mut pic_shape = vec![n];
    pic_shape.extend(picture_shape(kind));
    let pics = PyArray1::from_vec(py, pictures).reshape(pic_shape)?;
    Ok((out, pics).into_pyobject(py)?.into_any())
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(environments, m)?)?;
    m.add_function(wrap_pyfunction!(rollout, m)?)?;
    m.add_class::<PyEnv>()?;
    Ok(())
}
