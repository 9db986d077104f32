# How often can H2's b_i pass Shapiro-Wilk at all? (docs/calibration.md, "H2 normality")
#
# The paper's design fixes b_i's shape: b_i = m_i1 m_i2 m_i3, each m_ij the share of 7 scorers
# preferring the montage (420 comparisons = 20 animators x 3 takes x 7). This script draws studies
# of that design with no people model at all: each animator i has a probability p_i that a scorer
# prefers the montage, m_ij ~ Binomial(7, p_i) / 7, and p_i ~ Beta with mean mu and sd `between`
# (between = 0: identical animators, the most favourable case for normality). It reports the share
# of studies whose 20 b_i pass Shapiro-Wilk at 0.05 (R's shapiro.test, which mmh's test equals),
# and splits the failure into its two causes:
#   - "continuous": each share replaced by a Beta with the binomial's mean and variance (the
#     product's skew without the 8-level discreteness and its ties);
#   - "sum": m_i1 + m_i2 + m_i3 instead of the product (the discreteness without the product's
#     skew);
#   - "ks": Kolmogorov-Smirnov against the normal with the sample's mean and sd (no Lilliefors
#     correction), a much weaker goodness-of-fit test than Shapiro-Wilk.
# Usage: Rscript study/h2_normality_ceiling.R [studies per row, default 4000]
# Cost: about 1 s of CPU per 1000 studies and row.
args <- commandArgs(trailingOnly = TRUE)
studies <- if (length(args) >= 1) as.integer(args[1]) else 4000L
animators <- 20L; takes <- 3L; scorers <- 7L

draw_p <- function(mu, between) {
  if (between <= 0) return(rep(mu, animators))
  k <- mu * (1 - mu) / between^2 - 1
  rbeta(animators, mu * k, (1 - mu) * k)
}

row <- function(mu, between) {
  set.seed(2014)
  r <- replicate(studies, {
    p <- draw_p(mu, between)
    m <- matrix(rbinom(animators * takes, scorers, rep(p, takes)) / scorers, animators, takes)
    b <- apply(m, 1, prod)
    v <- p * (1 - p) / scorers
    k <- p * (1 - p) / v - 1
    mc <- matrix(rbeta(animators * takes, rep(p * k, takes), rep((1 - p) * k, takes)),
                 animators, takes)
    bc <- apply(mc, 1, prod)
    s <- rowSums(m)
    skew <- mean((b - mean(b))^3) / sd(b)^3
    c(mean_b = mean(b), sd_b = sd(b), skew = skew, distinct = length(unique(b)),
      zeros = sum(b == 0), normal = shapiro.test(b)$p.value > 0.05,
      normal_continuous = shapiro.test(bc)$p.value > 0.05,
      normal_sum = shapiro.test(s)$p.value > 0.05,
      # Kolmogorov-Smirnov against the normal with the sample's own mean and sd, without
      # Lilliefors' correction (a weak "goodness of fit test")
      normal_ks = suppressWarnings(ks.test(b, "pnorm", mean(b), sd(b))$p.value) > 0.05)
  })
  c(mu = mu, between = between, rowMeans(r))
}

grid <- expand.grid(between = c(0, 0.05, 0.1, 0.15), mu = c(0.60, 0.6457, 0.68, 0.72))
out <- t(mapply(row, grid$mu, grid$between))
print(round(out, 3))
