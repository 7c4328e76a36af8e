try:
    from twin.cli import main
except KeyboardInterrupt:  # Ctrl-C while the commands load: nothing has run yet
    from twin.errors import exit_interrupted

    exit_interrupted()

main()
