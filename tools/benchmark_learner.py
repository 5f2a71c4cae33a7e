"""Speed of the learner and the environment loop, as ratios against plain versions measured in the same run.

    python tools/benchmark_learner.py [--domain robostrich --task lesson1] [--hidden-sizes 256,256 --batch 256]
                                      [--json speed_learner.json]

Learner: updates/s of the jitted `lax.scan` update (agents.sac.learning) against
  (a) a plain SAC update written CleanRL-style: each loss jitted on its own,
      optimiser steps and Polyak averaging as separate calls from Python, one
      batch sampled and transferred per update;
  (b) the same plain update without jit (op-by-op dispatch), for scale.
Environment loop: steps/s of agents.loop.EnvironmentLoop acting with the policy
(no learning) against a plain loop (eager policy call, dict observations
flattened with Python lists, transitions appended to a list) and against raw
env.step with a fixed action; then with the training default's action repeat.
Variants are measured in interleaved rounds, best round kept, so that other
load on the machine biases the ratios as little as possible.
"""
import argparse
import dataclasses
import sys
import time

import jax
import jax.numpy as jnp
import numpy as np
import optax

from agents.robostrich.train.main_job import MAIN_JOB_SAC
from agents.robostrich.domains import as_domain
from agents.sac.builder import SACBuilder
from agents.sac.config import SACConfig
from agents.sac.learning import SACLearner, Transitions, init_state
from agents.sac.networks import make_networks
from robostrich_suite import speed_benchmarks


def plain_sac(networks, config):
    """A straightforward SAC update (same maths, same networks, same batch), no fusing, no scan."""
    q_opt, pi_opt, a_opt = optax.adam(config.learning_rate), optax.adam(config.learning_rate), optax.adam(config.learning_rate)
    target_entropy = -float(networks.action_size)

    def critic_loss(q_params, target_q_params, policy_params, alpha, b, key):
        na, nlp = networks.sample(policy_params, b.next_obs, key)
        t1, t2 = networks.q_apply(target_q_params, b.next_obs, na)
        target = jax.lax.stop_gradient(b.reward + config.discount * b.discount * (jnp.minimum(t1, t2) - alpha * nlp))
        q1, q2 = networks.q_apply(q_params, b.obs, b.action)
        return 0.5 * (jnp.mean((q1 - target) ** 2) + jnp.mean((q2 - target) ** 2))

    def actor_loss(policy_params, q_params, alpha, obs, key):
        a, lp = networks.sample(policy_params, obs, key)
        q1, q2 = networks.q_apply(q_params, obs, a)
        return jnp.mean(alpha * lp - jnp.minimum(q1, q2)), lp

    def alpha_loss(log_alpha, lp):
        return jnp.mean(-jnp.exp(log_alpha) * jax.lax.stop_gradient(lp + target_entropy))

    def make(jit):
        wrap = jax.jit if jit else (lambda f: f)
        critic_grad = wrap(jax.value_and_grad(critic_loss))
        actor_grad = wrap(jax.value_and_grad(actor_loss, has_aux=True))
        alpha_grad = wrap(jax.value_and_grad(alpha_loss))
        q_update, pi_update, a_update = wrap(q_opt.update), wrap(pi_opt.update), wrap(a_opt.update)
        apply = wrap(optax.apply_updates)
        polyak = wrap(lambda new, old: optax.incremental_update(new, old, config.tau))

        def update(s, batch, key):
            k1, k2 = jax.random.split(key)
            alpha = jnp.exp(s["log_alpha"])
            _, g = critic_grad(s["q"], s["target_q"], s["pi"], alpha, batch, k1)
            u, s["q_opt"] = q_update(g, s["q_opt"], s["q"])
            s["q"] = apply(s["q"], u)
            (_, lp), g = actor_grad(s["pi"], s["q"], alpha, batch.obs, k2)
            u, s["pi_opt"] = pi_update(g, s["pi_opt"], s["pi"])
            s["pi"] = apply(s["pi"], u)
            _, g = alpha_grad(s["log_alpha"], lp)
            u, s["a_opt"] = a_update(g, s["a_opt"], s["log_alpha"])
            s["log_alpha"] = apply(s["log_alpha"], u)
            s["target_q"] = polyak(s["q"], s["target_q"])
            return s
        return update

    def initial(key):
        st = init_state(networks, config, key)  # the networks' parameters; its own optimisers' states
        return {"pi": st.policy_params, "q": st.q_params, "target_q": st.target_q_params,
                "pi_opt": pi_opt.init(st.policy_params), "q_opt": q_opt.init(st.q_params), "log_alpha": st.log_alpha,
                "a_opt": a_opt.init(st.log_alpha)}
    return make, initial


def random_replay(n, obs_size, act_size, rng):
    return Transitions(rng.normal(size=(n, obs_size)).astype(np.float32),
                       rng.uniform(-1, 1, (n, act_size)).astype(np.float32),
                       rng.normal(size=n).astype(np.float32), np.ones(n, np.float32),
                       rng.normal(size=(n, obs_size)).astype(np.float32))


def best_rates(variants: dict, seconds: float, rounds: int = 3) -> dict:
    """Calls/s of each variant, measured in interleaved rounds and keeping each one's best round.

    Interleaving and best-of make the ratios robust to other load on a shared machine.
    """
    for fn in variants.values():
        fn()  # warm-up / compile
    best = {name: 0.0 for name in variants}
    for _ in range(rounds):
        for name, fn in variants.items():
            n, start = 0, time.perf_counter()
            while time.perf_counter() - start < seconds / rounds:
                fn()
                n += 1
            best[name] = max(best[name], n / (time.perf_counter() - start))
    return best


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--domain", default="robostrich", help="the domain whose observations and actions are used")
    p.add_argument("--task", default="lesson1", help="the task stepped by the environment loops")
    p.add_argument("--hidden-sizes", default="256,256", help="comma-separated hidden layer sizes")
    p.add_argument("--batch", type=int, default=256, help="transitions per update")
    p.add_argument("--updates-per-call", type=int, default=8, help="updates fused into one learner call")
    p.add_argument("--seconds", type=float, default=4.0, help="measuring time per variant (split in rounds)")
    p.add_argument("--action-repeat", type=int, default=5, help="action repeat of the last loop measured")
    p.add_argument("--json", default=None, help="also write the rates and ratios here (a results record's input)")
    args = p.parse_args(argv)
    env = as_domain(args.domain).make_environment(args.task, 0)
    config = dataclasses.replace(MAIN_JOB_SAC,  # robostrich-train's agent, these on top
                                 batch_size=args.batch, hidden_sizes=tuple(int(h) for h in args.hidden_sizes.split(",")),
                                 updates_per_call=args.updates_per_call, min_replay_size=0,
                                 # the same computation as the plain implementation it is compared with
                                 critic_layer_norm=False, her_ratio=0.0, relabel_rewards=False)
    loop = SACBuilder(config).make_components(env, seed=0)
    obs_size, act_size = loop.flattener.size, loop.actor.adapter.size
    networks = make_networks(obs_size, act_size, config.hidden_sizes)
    rng = np.random.default_rng(0)
    replay = random_replay(100_000, obs_size, act_size, rng)
    print(f"{args.domain}/{args.task}: obs {obs_size}, action {act_size}, hidden {config.hidden_sizes}, "
          f"batch {config.batch_size}, jax {jax.__version__} on {jax.devices()[0].platform}")

    # --- learner -----------------------------------------------------------------------
    learner = SACLearner(networks, config, jax.random.PRNGKey(0))
    k = config.updates_per_call

    def ours():
        idx = rng.integers(0, 100_000, (k, config.batch_size))
        m = learner.step(Transitions(*(x[idx] for x in replay)))
        m["critic_loss"].block_until_ready()

    make, initial = plain_sac(networks, config)
    variants = {"ours": ours}
    for name, jit in (("plain_jit_per_loss", True), ("plain_eager", False)):
        update, state = make(jit), initial(jax.random.PRNGKey(0))

        def plain(update=update, state=state, key=[jax.random.PRNGKey(1)]):
            idx = rng.integers(0, 100_000, config.batch_size)
            batch = Transitions(*(jnp.asarray(x[idx]) for x in replay))
            key[0], sub = jax.random.split(key[0])
            jax.block_until_ready(update(state, batch, sub)["target_q"])
        variants[name] = plain
    results = best_rates(variants, args.seconds * 3)
    results["ours"] *= k
    print("learner updates/s:")
    print(f"  ours (one jit, lax.scan x{k})       {results['ours']:9.1f}")
    print(f"  plain SAC, each loss jitted          {results['plain_jit_per_loss']:9.1f}   "
          f"ratio ours/plain = {results['ours'] / results['plain_jit_per_loss']:.2f}x")
    print(f"  plain SAC, no jit                    {results['plain_eager']:9.1f}   "
          f"ratio ours/eager = {results['ours'] / results['plain_eager']:.1f}x")

    # --- environment loop ----------------------------------------------------------------
    chunk = 250
    loop.replay.size = 0  # act with the policy but never learn: measures the acting path only
    never = SACConfig.LIMITS["env_steps_per_call"]  # no learner call within a measurement
    loop.config = SACConfig(**{**config.to_dict(), "min_replay_size": 0, "env_steps_per_call": never,
                               "hidden_sizes": config.hidden_sizes, "action_repeat": 1})
    policy_apply = networks.policy_apply  # eager haiku apply, the obvious first version
    params = learner.policy_params
    adapter = loop.actor.adapter
    plain_env = as_domain(args.domain).make_environment(args.task, 1)
    plain_state = {"ts": plain_env.reset(), "key": jax.random.PRNGKey(0), "transitions": []}

    def plain_loop():
        for _ in range(chunk // 5):
            ts = plain_state["ts"]
            obs = jnp.asarray(np.concatenate([np.ravel(v) for v in ts.observation.values()])[None], jnp.float32)
            plain_state["key"], sub = jax.random.split(plain_state["key"])
            mean, log_std = policy_apply(params, obs)
            a = np.asarray(jnp.tanh(mean + jnp.exp(log_std) * jax.random.normal(sub, mean.shape)))[0]
            nts = plain_env.step(adapter.to_env(a))
            plain_state["transitions"].append((ts.observation, a, nts.reward, nts.discount, nts.observation))
            plain_state["ts"] = plain_env.reset() if nts.last() else nts

    raw_env = as_domain(args.domain).make_environment(args.task, 2)
    raw_env.reset()
    action = adapter.to_env(np.zeros(act_size))

    def raw():
        for _ in range(chunk):
            if raw_env.step(action).last():
                raw_env.reset()

    repeat_loop = SACBuilder(SACConfig(**{**loop.config.to_dict(), "action_repeat": args.action_repeat,
                                          "hidden_sizes": config.hidden_sizes})).make_components(
        as_domain(args.domain).make_environment(args.task, 3), seed=0)
    repeat_loop.actor.update(params)
    rates = best_rates({"ours": lambda: loop.run(chunk), "plain": plain_loop, "raw": raw,
                        "ours_repeat": lambda: repeat_loop.run(chunk)}, args.seconds * 4)
    ours_sps, raw_sps, repeat_sps = rates["ours"] * chunk, rates["raw"] * chunk, rates["ours_repeat"] * chunk
    plain_sps = rates["plain"] * (chunk // 5)
    print("control steps/s (acting, no learning):")
    print(f"  ours (EnvironmentLoop)               {ours_sps:9.1f}")
    print(f"  plain loop (eager policy, lists)     {plain_sps:9.1f}   ratio ours/plain = {ours_sps / plain_sps:.1f}x")
    print(f"  raw env.step, fixed action           {raw_sps:9.1f}   ours reaches {ours_sps / raw_sps:.0%} of raw")
    print(f"  ours, action repeat {args.action_repeat}              {repeat_sps:9.1f}")
    ud = config.update_to_data_ratio
    per_step = 1.0 / repeat_sps + ud / (args.action_repeat * results["ours"])
    print(f"training throughput estimate (action repeat {args.action_repeat}, {ud:g} update per transition): "
          f"{1.0 / per_step:.0f} control steps/s")
    if args.json:
        speed_benchmarks.write_report(
            args.json, __file__, argv if argv is not None else sys.argv[1:],
            f"the learner's jitted update ({config.hidden_sizes} networks, batch {config.batch_size}, "
            f"{k} updates fused) and the acting loop on {args.domain}/{args.task}, each against a plain "
            "version in the same run; variants in interleaved rounds, the best round of each kept",
            [speed_benchmarks.rate(f"learner, one jit with lax.scan x{k}", results["ours"], "updates/s"),
             speed_benchmarks.rate("plain SAC update, each loss jitted", results["plain_jit_per_loss"], "updates/s"),
             speed_benchmarks.rate("EnvironmentLoop acting", ours_sps, "control steps/s"),
             speed_benchmarks.rate("raw env.step, fixed action", raw_sps, "control steps/s")],
            [speed_benchmarks.ratio("learner / plain SAC update, each loss jitted",
                                results["ours"] / results["plain_jit_per_loss"]),
             speed_benchmarks.ratio("learner / plain SAC update without jit", results["ours"] / results["plain_eager"]),
             speed_benchmarks.ratio("EnvironmentLoop / plain loop (eager policy, lists)", ours_sps / plain_sps),
             speed_benchmarks.ratio("EnvironmentLoop / raw env.step", ours_sps / raw_sps)])
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
