"""`python -m tmclsim`: the `tmclsim` command."""

from tmclsim._cli import main

if __name__ == "__main__":
    main()
