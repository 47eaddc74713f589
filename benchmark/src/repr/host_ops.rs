//! The transcendental functions of the networks' latent middle (exp, log, powf, softplus,
//! sigmoid) and of the burn engine's pixel loss (log-sigmoid) on burn tensors, computed by the
//! `libm` crate: burn's own ops call the platform's libm, whose variants are chosen by CPU
//! feature, so a run's bytes would depend on the machine (README "Reproducibility").

use burn::tensor::{Tensor, TensorData};

/// `f` applied elementwise on the host, as a tensor whose value is exactly `f(x)` and whose
/// gradient is `df(x, f(x))`. Built as `y + (x - detach(x)) * g` with `y` and `g` constants:
/// `x - detach(x)` is exactly zero forward and the identity backward.
pub fn host_map(x: Tensor<2>, f: impl Fn(f32) -> f32, df: impl Fn(f32, f32) -> f32) -> Tensor<2> {
    let [rows, cols] = x.dims();
    let device = x.device();
    let xs = (x.clone().into_data().convert::<f32>())
        .try_into_vec::<f32>()
        .expect("converted to f32");
    let ys: Vec<f32> = xs.iter().map(|&v| f(v)).collect();
    let gs: Vec<f32> = xs.iter().zip(&ys).map(|(&v, &y)| df(v, y)).collect();
    let y = Tensor::from_data(TensorData::new(ys, [rows, cols]), &device);
    let g = Tensor::from_data(TensorData::new(gs, [rows, cols]), &device);
    y + (x.clone() - x.detach()) * g
}

/// `exp` by [`host_map`].
pub fn exp(x: Tensor<2>) -> Tensor<2> {
    host_map(x, libm::expf, |_, y| y)
}

/// The natural logarithm by [`host_map`].
pub fn log(x: Tensor<2>) -> Tensor<2> {
    host_map(x, libm::logf, |v, _| 1.0 / v)
}

/// `x^p` by [`host_map`].
pub fn powf(x: Tensor<2>, p: f32) -> Tensor<2> {
    host_map(x, |v| libm::powf(v, p), |v, _| p * libm::powf(v, p - 1.0))
}

/// The logistic sigmoid by [`host_map`].
pub fn sigmoid(x: Tensor<2>) -> Tensor<2> {
    host_map(x, |v| 1.0 / (1.0 + libm::expf(-v)), |_, y| y * (1.0 - y))
}

/// `ln(1 + e^x)` by [`host_map`], linear above 20 (burn's threshold).
pub fn softplus(x: Tensor<2>) -> Tensor<2> {
    host_map(
        x,
        |v| {
            if v > 20.0 {
                v
            } else {
                libm::log1pf(libm::expf(v))
            }
        },
        |v, _| {
            if v > 20.0 {
                1.0
            } else {
                1.0 / (1.0 + libm::expf(-v))
            }
        },
    )
}

/// `ln sigmoid(x) = -softplus(-x)` by [`host_map`] (the burn engine's pixel loss).
pub fn log_sigmoid(x: Tensor<2>) -> Tensor<2> {
    host_map(
        x,
        |v| {
            if v < -20.0 {
                v
            } else {
                -libm::log1pf(libm::expf(-v))
            }
        },
        |v, _| {
            if v < -20.0 {
                1.0
            } else {
                1.0 / (1.0 + libm::expf(v))
            }
        },
    )
}

#[cfg(test)]
mod tests {
    use burn::tensor::activation;
    use burn::tensor::{Device, Tensor, TensorData};

    fn input(values: &[f32]) -> Tensor<2> {
        let device = Device::flex().autodiff();
        Tensor::from_data(
            TensorData::new(values.to_vec(), [2, values.len() / 2]),
            &device,
        )
        .require_grad()
    }

    fn values(t: Tensor<2>) -> Vec<f32> {
        t.into_data().try_into_vec::<f32>().unwrap()
    }

    /// Value and gradient of `ours` and of burn's `theirs` at `xs`, within `tol` relative.
    fn agree(
        xs: &[f32],
        ours: impl Fn(Tensor<2>) -> Tensor<2>,
        theirs: impl Fn(Tensor<2>) -> Tensor<2>,
        tol: f32,
    ) {
        let (a, b) = (input(xs), input(xs));
        let (ya, yb) = (ours(a.clone()), theirs(b.clone()));
        // A weighted sum, so that each element's gradient is scaled differently.
        let w: Vec<f32> = (0..xs.len()).map(|i| 1.0 + i as f32).collect();
        let wt = Tensor::from_data(TensorData::new(w, [2, xs.len() / 2]), &a.device());
        let ga = values(a.grad(&(ya.clone() * wt.clone()).sum().backward()).unwrap());
        let gb = values(b.grad(&(yb.clone() * wt).sum().backward()).unwrap());
        for (what, u, v) in [("value", values(ya), values(yb)), ("gradient", ga, gb)] {
            for (i, (p, q)) in u.iter().zip(&v).enumerate() {
                assert!(
                    (p - q).abs() <= tol * q.abs().max(1e-30),
                    "{what} {i} at x = {}: {p} against burn's {q}",
                    xs[i]
                );
            }
        }
    }

    const XS: [f32; 8] = [-25.0, -3.5, -0.7, -1e-3, 0.0, 0.4, 2.25, 30.0];

    #[test]
    fn the_host_functions_equal_burns_in_value_and_gradient() {
        agree(&XS, super::exp, |x| x.exp(), 1e-6);
        agree(&XS, super::sigmoid, activation::sigmoid, 1e-6);
        agree(&XS, super::softplus, |x| activation::softplus(x, 1.0), 1e-6);
        let positive = XS.map(|v| v.abs() + 0.125);
        agree(&positive, super::log, |x| x.log(), 1e-6);
        agree(
            &positive,
            |x| super::powf(x, 9.0),
            |x| x.powf_scalar(9.0),
            1e-5,
        );
        agree(&XS, super::log_sigmoid, activation::log_sigmoid, 1e-6);
        agree(&XS, |x| super::powf(x, 1.0), |x| x.powf_scalar(1.0), 1e-6);
    }

    #[test]
    fn the_value_is_exactly_the_host_functions() {
        let y = values(super::exp(input(&XS)));
        let want: Vec<f32> = XS.iter().map(|&v| libm::expf(v)).collect();
        assert_eq!(y, want);
    }
}
