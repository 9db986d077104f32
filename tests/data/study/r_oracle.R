# Helpers shared by make_golden.R and analyze_study.R: a JSON writer with 17 significant digits
# and the lmer fit at the exact REML optimum (see make_golden.R's header).
suppressPackageStartupMessages({
  library(lme4)
  library(lmerTest)
})

# ---- a small JSON writer with 17 significant digits (jsonlite stops at 15) ----
json_value <- function(v) {
  if (is.null(v)) return("null")
  if (is.list(v)) {
    if (!is.null(names(v)) && all(names(v) != "")) {
      items <- vapply(names(v), function(k) paste0("\"", k, "\": ", json_value(v[[k]])), "")
      return(paste0("{", paste(items, collapse = ", "), "}"))
    }
    return(paste0("[", paste(vapply(v, json_value, ""), collapse = ", "), "]"))
  }
  if (is.matrix(v)) {
    rows <- lapply(seq_len(nrow(v)), function(i) as.vector(v[i, ]))
    return(paste0("[", paste(vapply(rows, function(r) json_array(r), ""), collapse = ", "), "]"))
  }
  if (length(v) == 1 && !inherits(v, "AsIs")) return(json_scalar(v))
  json_array(v)
}
json_scalar <- function(x) {
  if (is.character(x)) return(paste0("\"", gsub("\"", "\\\\\"", x), "\""))
  if (is.logical(x)) return(if (is.na(x)) "null" else if (x) "true" else "false")
  if (!is.finite(x)) return("null")
  if (x == round(x) && abs(x) < 1e15) return(sprintf("%.0f", x))
  sprintf("%.17g", x)
}
json_array <- function(v) paste0("[", paste(vapply(as.list(v), json_scalar, ""), collapse = ", "), "]")
num <- function(x) unname(as.numeric(x))
vec <- function(x) I(unname(as.numeric(x)))  # always an array, even of length 1

# The REML score d/dpsi of the profiled REML deviance, psi = theta^2, in plain dense matrix algebra
# (Harville 1977): tr(P G) - (N - p) y'P G P y / y'P y, with V = I + psi Z Z', G = Z Z' and
# P = V^-1 - V^-1 X (X'V^-1 X)^-1 X'V^-1. Its root is lmer's optimum; found to the last bits here
# because lmer's optimiser and numerical gradients stop at ~1e-8 and ~1e-11.
reml_score <- function(psi, X, Z, y) {
  V <- diag(nrow(X)) + psi * tcrossprod(Z)
  Vi <- solve(V)
  ViX <- Vi %*% X
  P <- Vi - ViX %*% solve(crossprod(X, ViX), t(ViX))
  G <- tcrossprod(Z)
  Py <- P %*% y
  sum(diag(P %*% G)) - (nrow(X) - ncol(X)) * drop(crossprod(Py, G %*% Py)) / drop(crossprod(y, Py))
}
fit_refined <- function(d) {
  f <- y ~ take + (1 | animator)
  m0 <- suppressMessages(lmer(f, data = d, REML = TRUE))
  devf <- suppressMessages(lmer(f, data = d, REML = TRUE, devFunOnly = TRUE))
  X <- getME(m0, "X")
  Z <- as.matrix(getME(m0, "Z"))
  score <- function(psi) reml_score(psi, X, Z, d$y)
  th0 <- num(getME(m0, "theta"))
  candidates <- if (score(0) >= 0) 0 else numeric(0)
  if (th0 > 1e-6) {
    lo <- th0^2 / 2
    hi <- th0^2 * 2
    candidates <- c(candidates, sqrt(uniroot(score, c(lo, hi), tol = 1e-300, maxiter = 2000)$root))
  }
  th <- candidates[which.min(vapply(candidates, devf, 0))]
  # lme4's own deviance must agree that th is its optimum.
  stopifnot(devf(th) <= devf(th0) + 1e-12)
  m <- suppressMessages(lmer(f, data = d, REML = TRUE, start = list(theta = th),
                             control = lmerControl(optimizer = NULL)))
  list(m0 = m0, m = m, theta = th)
}
anova_row <- function(m) {
  a <- suppressWarnings(suppressMessages(anova(m)))
  list(sum_sq = num(a[["Sum Sq"]]), mean_sq = num(a[["Mean Sq"]]), num_df = num(a$NumDF),
       den_df = num(a$DenDF), f = num(a[["F value"]]), p_value = num(a[["Pr(>F)"]]))
}
